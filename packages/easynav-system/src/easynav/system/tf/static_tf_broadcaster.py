"""StaticTFBroadcaster: publishes static transforms, latched, on the relative ``tf_static``."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from easynav.common.tf.tf_buffer import TFBuffer
from easynav.core.types import TransformStamped
from easynav.system.tf.ros_conversion import message_values, to_message
from easynav.system.tf.tf_broadcaster import _as_list


class StaticTFBroadcaster:
    """Publishes ``tf2_msgs/msg/TFMessage`` on ``topic`` (``"tf_static"``), transient-local.

    As tf2_ros's StaticTransformBroadcaster: the publisher keeps only its last message, so every
    call republishes all the static transforms sent so far (the newest per child frame), and a
    listener that joins later still receives the whole set.

    Thread contract: ``send_transform`` may be called from any thread; it is locked by the GIL
    only for the dict update, so calls from two threads may publish in either order (the set
    published last is complete either way). Exceptions: as :class:`TFBroadcaster`.
    """

    def __init__(
        self, node: Any, topic: str = "tf_static", local_buffer: TFBuffer | None = None
    ) -> None:
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from tf2_msgs.msg import TFMessage

        self._message_type = TFMessage
        qos = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        self._node = node
        self._publisher = node.create_publisher(TFMessage, topic, qos)
        self._local_buffer = local_buffer
        self._authority = node.get_fully_qualified_name()
        self._sent: dict[str, Any] = {}

    def send_transform(self, transforms: TransformStamped | Any | Iterable[Any]) -> None:
        """Add (or replace, per child frame) static transforms and republish them all."""
        msgs = [to_message(t) for t in _as_list(transforms)]
        for msg in msgs:
            self._sent[msg.child_frame_id] = msg
        self._publisher.publish(self._message_type(transforms=list(self._sent.values())))
        if self._local_buffer is not None:
            for msg in msgs:
                parent, child, stamp, values = message_values(msg)
                self._local_buffer.set_transform_values(
                    parent, child, stamp, values, self._authority, True
                )

    def destroy(self) -> None:
        """Destroy the publisher."""
        self._node.destroy_publisher(self._publisher)
