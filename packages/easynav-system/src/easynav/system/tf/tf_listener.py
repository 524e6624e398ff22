"""TFListener: fills a TFBuffer from the node-relative ``tf`` and ``tf_static`` topics."""

from __future__ import annotations

import re
from typing import Any

from easynav.common.tf.tf_buffer import TFBuffer
from easynav.common.tf.tf_buffer_registry import get_tf_buffer
from easynav.system.cycle_times import CycleTimes
from easynav.system.tf.ros_conversion import stamp_to_seconds

#: The line :meth:`TFListener.describe_odometry_age` writes; tools that read EasyNav's log (the
#: playground demo's summary) parse it with this.
ODOMETRY_AGE_PATTERN = re.compile(
    r"age of (?P<parent>\S+) → (?P<child>\S+) when served: (?P<count>\d+) transforms, "
    r"median (?P<median>-?[\d.]+) ms, p99 (?P<p99>-?[\d.]+) ms, max (?P<max>-?[\d.]+) ms"
)


class TFListener:
    """Subscribes ``tf`` (reliable, depth 100) and ``tf_static`` (reliable, transient-local).

    Topics are relative to the node's namespace, so each robot of a multi-robot setup (one
    namespace each) fills its own tree. ``buffer`` None uses ``get_tf_buffer(<node namespace>)``.
    Callbacks run in whichever executor spins ``node`` (``callback_group`` chooses the group).

    When the node's clock jumps back (a simulator or a bag restarted) or switches between
    system and simulated time, the buffer is cleared, as tf2's buffer does: the transforms
    stamped on the old time line would otherwise be taken for the newest for up to the cache
    window, and every new one refused as too old.

    Thread contract: construct and ``destroy`` in the node's configuring thread; the callbacks
    only call :meth:`TFBuffer.set_transform_values`, which is locked; the clock's jump
    callback (in whichever thread sets the clock) only calls :meth:`TFBuffer.clear`, locked
    too. A bad transform in a message is rejected by the buffer with a warning; the rest of
    the message is still used.
    """

    def __init__(
        self,
        node: Any,
        buffer: TFBuffer | None = None,
        callback_group: Any = None,
        tf_topic: str = "tf",
        tf_static_topic: str = "tf_static",
    ) -> None:
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from tf2_msgs.msg import TFMessage

        self.buffer = buffer if buffer is not None else get_tf_buffer(node.get_namespace())
        self._node = node
        self.odometry_age = CycleTimes()
        dynamic_qos = QoSProfile(
            depth=100,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
        static_qos = QoSProfile(
            depth=100,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        self._subscriptions = [
            node.create_subscription(
                TFMessage, tf_topic, self._on_tf, dynamic_qos, callback_group=callback_group
            ),
            node.create_subscription(
                TFMessage,
                tf_static_topic,
                self._on_tf_static,
                static_qos,
                callback_group=callback_group,
            ),
        ]
        from rclpy.clock import JumpThreshold
        from rclpy.duration import Duration

        self._jump_handle = node.get_clock().create_jump_callback(
            JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=-1)),
            post_callback=self._on_time_jump,
        )

    def _on_time_jump(self, jump: Any) -> None:
        from rclpy.clock import ClockChange

        if jump.clock_change in (ClockChange.ROS_TIME_ACTIVATED, ClockChange.ROS_TIME_DEACTIVATED):
            reason = "the time source changed"
        elif jump.delta.nanoseconds < 0:
            reason = f"time jumped back {-jump.delta.nanoseconds * 1e-9:.3f} s"
        else:
            return
        if self.buffer.frames():
            self._node.get_logger().warning(f"{reason}: clearing the TF buffer")
        self.buffer.clear()

    def _on_tf(self, msg: Any) -> None:
        self._store(msg, "tf", False)
        robot = self.buffer.get_tf_info().robot_footprint_frame
        for ts in msg.transforms:
            if ts.child_frame_id == robot:
                now = self._node.get_clock().now().nanoseconds * 1e-9
                self.odometry_age.record(now - stamp_to_seconds(ts.header.stamp))
                break

    def describe_odometry_age(self) -> str | None:
        """One log line (matching :data:`ODOMETRY_AGE_PATTERN`) on ``odometry_age``; None
        before the first ``odom → robot`` transform."""
        stats = self.odometry_age.summary()
        if stats is None:
            return None
        median, p99, worst = (1e3 * v for v in stats)
        info = self.buffer.get_tf_info()
        return (
            f"age of {info.odom_frame} → {info.robot_footprint_frame} when served: "
            f"{self.odometry_age.count} transforms, median {median:.1f} ms, p99 {p99:.1f} ms, "
            f"max {worst:.1f} ms"
        )

    def _on_tf_static(self, msg: Any) -> None:
        self._store(msg, "tf_static", True)

    def _store(self, msg: Any, topic: str, is_static: bool) -> None:
        buffer = self.buffer
        for ts in msg.transforms:
            t = ts.transform.translation
            q = ts.transform.rotation
            buffer.set_transform_values(
                ts.header.frame_id,
                ts.child_frame_id,
                stamp_to_seconds(ts.header.stamp),
                (t.x, t.y, t.z, q.x, q.y, q.z, q.w),
                topic,
                is_static,
            )

    def destroy(self) -> None:
        """Destroy both subscriptions and the clock's jump callback."""
        if self._jump_handle is not None:
            self._jump_handle.unregister()
            self._jump_handle = None
        for sub in self._subscriptions:
            self._node.destroy_subscription(sub)
        self._subscriptions = []
