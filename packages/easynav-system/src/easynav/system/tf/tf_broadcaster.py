"""TFBroadcaster: publishes dynamic transforms on the node-relative ``tf`` topic."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from easynav.common.tf.tf_buffer import TFBuffer
from easynav.core.types import TransformStamped
from easynav.system.tf.ros_conversion import message_values, to_message

# tf2_ros's DynamicBroadcasterQoS: reliable, volatile, keep last 100.
_TF_DEPTH = 100


class TFBroadcaster:
    """Publishes ``tf2_msgs/msg/TFMessage`` on ``topic`` (``"tf"``, relative to the namespace).

    The topic is relative so that a robot in namespace ``r1`` publishes on ``/r1/tf`` and keeps
    its own tree. With ``local_buffer`` the transforms also go straight into that buffer, so this
    process sees them at once without waiting for its own listener.

    Thread contract: ``send_transform`` may be called from any thread (rclpy publishers are
    thread-safe). Exceptions: ``TypeError`` for an object that is not a transform, ``ValueError``
    naming the frames for a non-finite one (nothing of the call is published then).
    """

    def __init__(self, node: Any, topic: str = "tf", local_buffer: TFBuffer | None = None) -> None:
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from tf2_msgs.msg import TFMessage

        self._message_type = TFMessage
        qos = QoSProfile(
            depth=_TF_DEPTH,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
        self._node = node
        self._publisher = node.create_publisher(TFMessage, topic, qos)
        self._local_buffer = local_buffer
        self._authority = node.get_fully_qualified_name()

    def send_transform(self, transforms: TransformStamped | Any | Iterable[Any]) -> None:
        """Publish one transform or a list of them (native or geometry_msgs) in one message."""
        items = _as_list(transforms)
        msgs = [to_message(t) for t in items]
        self._publisher.publish(self._message_type(transforms=msgs))
        if self._local_buffer is not None:
            for msg in msgs:
                parent, child, stamp, values = message_values(msg)
                self._local_buffer.set_transform_values(
                    parent, child, stamp, values, self._authority, False
                )

    def destroy(self) -> None:
        """Destroy the publisher."""
        self._node.destroy_publisher(self._publisher)


def _as_list(transforms: Any) -> list[Any]:
    if isinstance(transforms, (list, tuple)):
        return list(transforms)
    if hasattr(transforms, "child_frame_id"):
        return [transforms]
    return list(transforms)
