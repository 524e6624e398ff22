"""The test harness of the end-to-end safety suite: the robot's driver, the safety PLC and a
heartbeat receiver, each a node of the test's own ROS context (``ros`` fixture), talking to a
running EasyNav over real topics.

Callbacks and timers run only while the test spins its executor (``ros.spin_for`` /
``ros.spin_until``): tests wait by spinning, never by sleeping, so the PLC keeps publishing and
the driver keeps receiving.

Thread contract: everything here runs in the test's thread.
"""

from __future__ import annotations

import itertools
import math
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import pytest
from geometry_msgs.msg import Twist as TwistMsg
from geometry_msgs.msg import TwistStamped as TwistStampedMsg
from rclpy.duration import Duration
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.qos import (
    QoSDurabilityPolicy,
    QoSHistoryPolicy,
    QoSLivelinessPolicy,
    QoSProfile,
    QoSReliabilityPolicy,
)

from easynav.core.robot import RobotLimits
from easynav.core.types import Twist
from easynav.system.testing.dds_isolation import FAST_ANNOUNCEMENTS_PROFILE
from easynav.system.testing.ros_fixtures import RosTestContext

_names = itertools.count()


def _sched_fifo_allowed() -> bool:
    from easynav.system.safety import try_sched_fifo

    return try_sched_fifo()[0]


#: Safety mode requires SCHED_FIFO (refused on configure otherwise): root has it (unless a container
#: dropped CAP_SYS_NICE), a normal user only when granted RLIMIT_RTPRIO. It is tried, as configure
#: does, and tests that configure in safety mode are skipped, with this reason, where it is refused.
requires_sched_fifo = pytest.mark.skipif(
    not _sched_fifo_allowed(),
    reason=(
        f"safety mode needs SCHED_FIFO, refused here (euid {os.geteuid()}): run as root, or "
        "grant RLIMIT_RTPRIO / CAP_SYS_NICE (packages/easynav-system/docs/safety.md)"
    ),
)

# Tolerances of the checks: a stamp is the node clock in float seconds (resolution 0.24 µs at
# today's epoch), then rounded to ns in builtin_interfaces/Time; velocities are float sums.
STAMP_EPS = 1e-6  # s
EPS = 1e-6  # m/s, rad/s


def _twist(msg: TwistMsg) -> Twist:
    return Twist(
        msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x, msg.angular.y, msg.angular.z
    )


def _stamp(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def _receiver_qos(deadline: float | None, liveliness_lease: float | None, depth: int) -> QoSProfile:
    qos = QoSProfile(
        history=QoSHistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=QoSReliabilityPolicy.RELIABLE,
        durability=QoSDurabilityPolicy.VOLATILE,
    )
    if deadline is not None:
        qos.deadline = Duration(seconds=deadline)
    if liveliness_lease is not None:
        qos.liveliness = QoSLivelinessPolicy.MANUAL_BY_TOPIC
        qos.liveliness_lease_duration = Duration(seconds=liveliness_lease)
    return qos


@dataclass
class Sample:
    """One command as the driver received it."""

    stamp: float  # header stamp (node clock of the RT cycle); reception time for plain Twist
    received: float  # time.monotonic() at reception
    twist: Twist


@dataclass
class QoSEvents:
    """Deadline and liveliness events of one subscription (time.monotonic() of each)."""

    deadline_missed: list[float] = field(default_factory=list)
    liveliness_lost: list[float] = field(default_factory=list)

    def callbacks(self) -> SubscriptionEventCallbacks:
        return SubscriptionEventCallbacks(deadline=self._on_deadline, liveliness=self._on_live)

    def _on_deadline(self, info) -> None:
        self.deadline_missed.append(time.monotonic())

    def _on_live(self, info) -> None:
        if info.not_alive_count_change > 0:
            self.liveliness_lost.append(time.monotonic())

    def deadline_missed_after(self, t: float) -> bool:
        return any(e >= t for e in self.deadline_missed)


class RobotDriver:
    """The robot's driver: executes whatever arrives on ``cmd_vel`` (Twist) or, with
    ``stamped``, ``cmd_vel_stamped`` (TwistStamped), and records it.

    ``deadline`` / ``liveliness_lease`` (s): requested QoS, as a driver or safety controller that
    wants to know when EasyNav stops commanding would ask for (EasyNav offers twice
    ``cmd_vel_keepalive_period``); the events are counted in :attr:`events`.
    """

    def __init__(
        self,
        ros,
        stamped: bool = True,
        deadline: float | None = None,
        liveliness_lease: float | None = None,
        topic: str | None = None,
    ) -> None:
        self.stamped = stamped
        self.samples: list[Sample] = []
        self.events = QoSEvents()
        self.node = ros.create_node(f"robot_driver_{next(_names)}")
        qos = _receiver_qos(deadline, liveliness_lease, depth=10_000)
        if stamped:
            self.subscription = self.node.create_subscription(
                TwistStampedMsg,
                topic or "cmd_vel_stamped",
                self._on_stamped,
                qos,
                event_callbacks=self.events.callbacks(),
            )
        else:
            self.subscription = self.node.create_subscription(
                TwistMsg,
                topic or "cmd_vel",
                self._on_twist,
                qos,
                event_callbacks=self.events.callbacks(),
            )

    def _on_twist(self, msg: TwistMsg) -> None:
        self.samples.append(Sample(time.time(), time.monotonic(), _twist(msg)))

    def _on_stamped(self, msg: TwistStampedMsg) -> None:
        self.frame_id = msg.header.frame_id
        self.samples.append(Sample(_stamp(msg), time.monotonic(), _twist(msg.twist)))

    def connected(self) -> bool:
        """True once EasyNav's velocity publisher is matched."""
        return self.subscription.get_publisher_count() > 0

    def last(self) -> Twist | None:
        return self.samples[-1].twist if self.samples else None

    def last_is(self, predicate) -> bool:
        return bool(self.samples) and predicate(self.samples[-1].twist)

    def received_after(self, monotonic_time: float) -> list[Sample]:
        """Samples received at or after ``monotonic_time`` (test's ``time.monotonic()``)."""
        return [s for s in self.samples if s.received >= monotonic_time]

    def stamped_after(self, stamp: float) -> list[Sample]:
        """Samples whose stamp is at or after ``stamp`` (node clock)."""
        return [s for s in self.samples if s.stamp >= stamp]


class PublishedCommands:
    """Every command a running EasyNav (in this process) publishes on its velocity topic, with
    its stamp, recorded as it is published: what was sent, none missed.

    The driver's record is what arrived, and the publisher keeps only the latest command
    (depth 1): on a loaded machine the driver misses some, a braking ramp's among them. The
    shape of a ramp is checked here; what the robot ends up doing, on the driver's side.
    Commands are published when they change (and every keepalive period, when set).
    """

    def __init__(self, rt) -> None:
        node = rt.system_node.controller_node
        self.samples: list[Sample] = []
        publish = node.publish_twist

        def recorded(twist: Twist, now: float) -> None:  # the RT thread
            self.samples.append(Sample(now, time.monotonic(), Twist(*twist.as_tuple())))
            publish(twist, now)

        node.publish_twist = recorded

    def stamped_after(self, stamp: float) -> list[Sample]:
        """Commands stamped at or after ``stamp`` (node clock)."""
        return [s for s in list(self.samples) if s.stamp >= stamp]


class SafetyPlc:
    """The certified safety channel's bridge: publishes ``easynav_interfaces/SafetyStatus`` on
    ``easynav_safety_status`` every ``period`` seconds while :attr:`publishing`.

    The state is changed with :meth:`release`, :meth:`protective_stop`, :meth:`limit_speed`,
    :meth:`send_invalid_limit` and :meth:`go_silent`; each publishes at once too.
    """

    def __init__(self, ros, period: float = 0.02, publishing: bool = True) -> None:
        from easynav_interfaces.msg import SafetyStatus

        self._type = SafetyStatus
        self.node = ros.create_node(f"safety_plc_{next(_names)}")
        self.publisher = self.node.create_publisher(
            SafetyStatus,
            "easynav_safety_status",
            QoSProfile(depth=10, reliability=QoSReliabilityPolicy.RELIABLE),
        )
        self.publishing = publishing
        self.state = {
            "protective_stop": False,
            "speed_limited": False,
            "max_linear_vel": 0.0,
            "max_angular_vel": 0.0,
            "active_field": "",
            "muting": False,
        }
        self.sent = 0
        self.timer = self.node.create_timer(period, self._publish_if_on)

    def connected(self) -> bool:
        return self.publisher.get_subscription_count() > 0

    def _publish_if_on(self) -> None:
        if self.publishing:
            self.publish()

    def publish(self) -> None:
        msg = self._type()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        for name, value in self.state.items():
            setattr(msg, name, value)
        self.publisher.publish(msg)
        self.sent += 1

    def _set(self, **state) -> None:
        self.state.update(state)
        self.publishing = True
        self.publish()

    def release(self) -> None:
        """No protective stop, no speed limit."""
        self._set(
            protective_stop=False,
            speed_limited=False,
            max_linear_vel=0.0,
            max_angular_vel=0.0,
            active_field="",
            muting=False,
        )

    def protective_stop(self, active_field: str = "protective_front") -> None:
        self._set(protective_stop=True, active_field=active_field)

    def limit_speed(self, linear: float, angular: float, active_field: str = "warning") -> None:
        self._set(
            protective_stop=False,
            speed_limited=True,
            max_linear_vel=linear,
            max_angular_vel=angular,
            active_field=active_field,
        )

    def send_invalid_limit(self) -> None:
        """A safely limited speed whose linear limit is NaN: not a valid status."""
        self._set(
            protective_stop=False, speed_limited=True, max_linear_vel=math.nan, max_angular_vel=0.5
        )

    def go_silent(self) -> None:
        """The bridge stops publishing (dead PLC bridge, cut cable)."""
        self.publishing = False


class HeartbeatReceiver:
    """A supervisor subscribed to ``easynav_heartbeat`` with a requested ``deadline``."""

    def __init__(
        self,
        ros,
        deadline: float,
        liveliness_lease: float | None = None,
        topic: str = "easynav_heartbeat",
    ) -> None:
        from easynav_interfaces.msg import Heartbeat

        self.messages: list[tuple[float, object]] = []  # (time.monotonic(), Heartbeat)
        self.events = QoSEvents()
        self.node = ros.create_node(f"heartbeat_receiver_{next(_names)}")
        self.subscription = self.node.create_subscription(
            Heartbeat,
            topic,
            self._on_heartbeat,
            _receiver_qos(deadline, liveliness_lease, depth=10_000),
            event_callbacks=self.events.callbacks(),
        )

    def _on_heartbeat(self, msg) -> None:
        self.messages.append((time.monotonic(), msg))

    def connected(self) -> bool:
        return self.subscription.get_publisher_count() > 0

    def received_after(self, monotonic_time: float) -> list:
        return [m for t, m in self.messages if t >= monotonic_time]


class RosoutListener:
    """Every log message of every node, as ``ros2 topic echo /rosout`` shows it (transient local:
    messages logged before the subscription also arrive)."""

    def __init__(self, ros) -> None:
        from rcl_interfaces.msg import Log

        self.messages: list[tuple[str, int, str]] = []  # (logger name, level, text)
        self.node = ros.create_node(f"rosout_listener_{next(_names)}")
        qos = QoSProfile(
            depth=1000,
            reliability=QoSReliabilityPolicy.RELIABLE,
            durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
        )
        self.subscription = self.node.create_subscription(Log, "/rosout", self._on_log, qos)

    def _on_log(self, msg) -> None:
        self.messages.append((msg.name, msg.level, msg.msg))

    def find(self, text: str) -> list[tuple[str, int, str]]:
        """Messages containing ``text``."""
        return [m for m in self.messages if text in m[2]]


def easynav_process_env() -> dict[str, str]:
    """The environment for an ``easynav`` subprocess: this process's (ROS domain, log directory)
    with the Fast DDS profile that announces its participant every 0.2 s instead of 3 s, so the
    test's nodes discover it at once (see ``easynav.system.testing.dds_isolation``).
    """
    return {**os.environ, "FASTRTPS_DEFAULT_PROFILES_FILE": str(FAST_ANNOUNCEMENTS_PROFILE)}


@contextmanager
def ros_context_after_start() -> Iterator[RosTestContext]:
    """A ROS context for the test's nodes, created once an ``easynav`` subprocess is up.

    Measured here (Fast DDS, discovery on localhost): a participant that already exists when
    another process starts discovered it only at the next periodic announcement, about 3 s later;
    one created after the process is up matches it at once (< 0.1 s) most of the time (and, with
    :func:`easynav_process_env`, within 0.6 s every time measured).
    """
    context = RosTestContext()
    try:
        yield context
    finally:
        context.shutdown()


# -- checks ----------------------------------------------------------------------------------
def assert_within_limits(samples: list[Sample], limits: RobotLimits) -> None:
    """Every command within the velocity limits, and every change between two consecutive
    commands within the acceleration (speeding up) or deceleration (slowing down) limits over
    the time between their stamps, never changing direction without passing through zero.
    """
    for s in samples:
        tw = s.twist
        assert tw.is_finite(), f"non-finite command reached the robot: {tw}"
        assert limits.min_linear_vel - EPS <= tw.vx <= limits.max_linear_vel + EPS, s
        assert abs(tw.wz) <= limits.max_angular_vel + EPS, s
    axes = (
        ("vx", limits.max_linear_acc, limits.max_linear_decel),
        ("wz", limits.max_angular_acc, limits.max_angular_decel),
    )
    for a, b in itertools.pairwise(samples):
        dt = b.stamp - a.stamp
        for axis, acc, dec in axes:
            before, after = getattr(a.twist, axis), getattr(b.twist, axis)
            assert before * after >= 0.0, f"{axis} reversed without stopping: {a} -> {b}"
            rate = acc if abs(after) > abs(before) else dec
            assert abs(after - before) <= rate * (dt + STAMP_EPS) + EPS, (
                f"{axis} {before:.4f} -> {after:.4f} in {dt * 1000:.2f} ms exceeds {rate}/s"
            )


def assert_ramps_up_from_zero(
    samples: list[Sample], limits: RobotLimits, rest_stamp: float
) -> None:
    """``samples`` start at rest and stay within limits: the robot resumes from zero, never
    from what was commanded before.

    ``rest_stamp``: a stamp (node clock) since which the commanded robot was known to be at
    rest (EasyNav's ramp start, the release of a stop). The driver does not see every command:
    the publisher keeps only the latest (depth 1) and a subscription matched a moment late
    misses the first ones, so the first non-zero command is checked against the last zero
    received before it or, without one, against ``rest_stamp``, over the time between their
    stamps.
    """
    assert samples, "no command received"
    moving = [s for s in samples if not s.twist.is_zero()]
    assert moving, "the robot never moved again"
    first = moving[0]
    zeros_before = [s for s in samples if s.stamp < first.stamp]
    reference = zeros_before[-1].stamp if zeros_before else rest_stamp
    dt = first.stamp - reference
    assert dt >= 0.0, (first, reference)
    assert abs(first.twist.vx) <= limits.max_linear_acc * (dt + STAMP_EPS) + EPS, (first, dt)
    assert abs(first.twist.wz) <= limits.max_angular_acc * (dt + STAMP_EPS) + EPS, (first, dt)
    assert_within_limits(samples, limits)


def at_rest_since(samples: list[Sample], stamp: float) -> float:
    """The stamp of the last command received before ``stamp`` when it was a zero: since then
    the robot has been commanded to stand still (``assert_ramps_up_from_zero``'s reference
    after a stop). AssertionError when the last command before ``stamp`` was not a zero.
    """
    before = [s for s in samples if s.stamp < stamp]
    assert before and before[-1].twist.is_zero(), (
        f"the robot was not commanded to stand still before {stamp}: {before[-1:]}"
    )
    return before[-1].stamp


def full_speed(twist: Twist | None, linear: float, angular: float) -> bool:
    return twist is not None and twist.vx == linear and twist.wz == angular
