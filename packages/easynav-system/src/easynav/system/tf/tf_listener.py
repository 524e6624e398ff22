"""TFListener: fills a TFBuffer from the node-relative ``tf`` and ``tf_static`` topics."""

from __future__ import annotations

import re
import threading
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


#: The ``odom → robot`` ages :attr:`TFListener.odometry_age` keeps: 33 min at 50 Hz.
ODOMETRY_AGE_SAMPLES = 100_000


class TFListener:
    """Subscribes ``tf`` (reliable, depth 100) and ``tf_static`` (reliable, transient-local).

    Topics are relative to the node's namespace, so each robot of a multi-robot setup (one
    namespace each) fills its own tree. ``buffer`` None uses ``get_tf_buffer(<node namespace>)``.
    Callbacks run in whichever executor spins ``node`` (``callback_group`` chooses the group).

    When the node's clock jumps back (a simulator or a bag restarted) or switches between
    system and simulated time, the dynamic transforms are cleared, as tf2's buffer does: those
    stamped on the old time line would otherwise be taken for the newest for up to the cache
    window, and every new one refused as too old. Static transforms stay (as in tf2): they hold
    at every time, and their publishers send them once per subscription. Transforms of the
    old time line that arrive after the clear (this subscription's backlog: ``/clock`` keeps
    only its newest message, ``tf`` up to 100) are refused (``TFBuffer.clear``'s
    ``refuse_after``) until the clock gets to where that time line begins (5 s at most):
    stamps over halfway back to where the clock was, or, after a switch to simulated time,
    within the cache window of the system time or later. Stored, one was the newest for as
    long as the jump, and after a jump longer than the window every transform of the new run
    was refused as older than it (tf2 has the same weakness).

    Between :meth:`start_odometry_age` and :meth:`stop_odometry_age` (system_node's activation
    and deactivation) ``odometry_age`` records how old each ``odom → robot`` transform stamped
    since the start was when its message was served: the node's clock minus the stamp. It is
    the transport's delay plus the backlog of the executor that serves the listener (the RT
    loop's): what every lookup of the robot's pose lags behind the robot. Transforms stamped
    before the start (queued while no loop served the listener, during configuration) are not
    counted. On simulated time the age is in simulated seconds: at twice real time a backlog of
    10 ms of wall time reads 20 ms.

    Thread contract: construct and ``destroy`` in the node's configuring thread;
    :meth:`start_odometry_age` and :meth:`stop_odometry_age` in its lifecycle thread. The
    callbacks call the locked :meth:`TFBuffer.set_transform_values` and
    :meth:`TFBuffer.get_tf_info`, read the node's clock and record into ``odometry_age``
    (unlocked: a reader while they run may see a torn last value); the clock's jump callback
    (in whichever thread sets the clock) calls :meth:`TFBuffer.clear`, locked too. The start
    of the measure is written under a lock by start, stop, the jump callback and the first
    callback after a start before the first ``/clock``. A bad
    transform in a message is rejected by the buffer with a warning; the rest of the message
    is still used.
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
        self.odometry_age = CycleTimes(ODOMETRY_AGE_SAMPLES)
        self._age_since: float | None = None  # node-clock seconds; None: not measuring
        self._age_lock = threading.Lock()  # start, stop and a clock jump: not the callback
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
        import time

        from rclpy.clock import ClockChange

        now = self._now()
        if jump.clock_change == ClockChange.ROS_TIME_ACTIVATED:
            reason = "the clock switched to simulated time"
            # Transforms stamped on the system time, still queued, are refused until the
            # simulated clock gets there (at once when it follows the system time: the first
            # transform served ends the refusal).
            refuse_after = time.time() - self.buffer.cache_time
        elif jump.clock_change == ClockChange.ROS_TIME_DEACTIVATED:
            reason = "the clock switched to the system time"
            refuse_after = None  # queued simulated stamps are older than the new ones
        elif jump.delta.nanoseconds < 0:
            back = -jump.delta.nanoseconds * 1e-9
            reason = f"time jumped back {back:.3f} s"
            # Queued transforms of the old time line are refused: those stamped over halfway
            # back to where the clock was.
            refuse_after = now + 0.5 * back
        else:
            return
        if self.buffer.frames():
            self._node.get_logger().warning(
                f"{reason}: clearing the TF buffer's dynamic transforms")
        self.buffer.clear(keep_static=True, refuse_after=refuse_after)
        with self._age_lock:
            if self._age_since is not None:  # the new time line's transforms count
                self._age_since = now

    def _now(self) -> float:
        return self._node.get_clock().now().nanoseconds * 1e-9

    def _on_tf(self, msg: Any) -> None:
        refusing_after = self.buffer.refusing_after
        if refusing_after is not None and self._now() >= refusing_after:
            self.buffer.end_refusal()  # the clock got past the old time line's start
        self._store(msg, "tf", False)
        since = self._age_since
        if since is None:
            return
        info = self.buffer.get_tf_info()
        for ts in msg.transforms:
            if (ts.child_frame_id.lstrip("/") == info.robot_footprint_frame
                    and ts.header.frame_id.lstrip("/") == info.odom_frame):
                now = self._now()
                if since <= 0.0:  # started before the first /clock: from the first reading
                    if now <= 0.0:
                        return
                    with self._age_lock:  # unless stopped or restarted meanwhile
                        if self._age_since is not None and self._age_since <= 0.0:
                            self._age_since = now
                        since = self._age_since
                    if since is None:
                        return
                stamp = stamp_to_seconds(ts.header.stamp)
                # Not counted: stamped before the start, or ahead of the clock by more than
                # a second (another time line: a transform queued across a clock jump).
                if since <= stamp <= now + 1.0:
                    self.odometry_age.record(now - stamp)
                break

    def start_odometry_age(self) -> None:
        """Record ``odometry_age`` afresh, for the transforms stamped from now on (on
        simulated time before the first ``/clock``: from its first reading)."""
        with self._age_lock:
            self.odometry_age = CycleTimes(ODOMETRY_AGE_SAMPLES)
            self._age_since = self._now()

    def stop_odometry_age(self) -> str | None:
        """Stop recording; :meth:`describe_odometry_age` of what was recorded."""
        with self._age_lock:
            self._age_since = None
        return self.describe_odometry_age()

    def describe_odometry_age(self) -> str | None:
        """One log line (matching :data:`ODOMETRY_AGE_PATTERN`) on ``odometry_age``; None
        before the first ``odom → robot`` transform. The statistics cover the last
        :data:`ODOMETRY_AGE_SAMPLES`; a torn last value is possible while the callback runs."""
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
