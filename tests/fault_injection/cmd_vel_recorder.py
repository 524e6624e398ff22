"""CmdVelRecorder: what reaches the robot, as a driver subscribed to EasyNav's output sees it."""

from __future__ import annotations

import itertools
import time

from geometry_msgs.msg import Twist as TwistMsg
from geometry_msgs.msg import TwistStamped as TwistStampedMsg
from rclpy.qos import QoSProfile, QoSReliabilityPolicy

from easynav.core.types import Twist

_names = itertools.count()


def _twist(msg: TwistMsg) -> Twist:
    return Twist(
        msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x, msg.angular.y, msg.angular.z
    )


class CmdVelRecorder:
    """Subscribes ``cmd_vel`` (Twist) or, with ``stamped``, ``cmd_vel_stamped`` (TwistStamped)
    on a node of the test's ROS context and keeps every command received.

    ``samples`` is a list of ``(time, Twist)``: the message stamp for ``cmd_vel_stamped`` (the
    node clock of the RT cycle that computed it, so the smoother's limits can be checked
    exactly), else the wall-clock time of reception (the node clock of a system without
    ``use_sim_time``). Messages arrive only while the test spins its executor.

    Thread contract: the test's thread (callbacks run in its ``spin_*`` calls).
    """

    def __init__(self, ros, stamped: bool = False) -> None:
        self.stamped = stamped
        self.samples: list[tuple[float, Twist]] = []
        self.node = ros.create_node(f"robot_driver_{next(_names)}")
        qos = QoSProfile(depth=1000, reliability=QoSReliabilityPolicy.RELIABLE)
        if stamped:
            self.subscription = self.node.create_subscription(
                TwistStampedMsg, "cmd_vel_stamped", self._on_stamped, qos
            )
        else:
            self.subscription = self.node.create_subscription(
                TwistMsg, "cmd_vel", self._on_twist, qos
            )

    def _on_twist(self, msg: TwistMsg) -> None:
        self.samples.append((time.time(), _twist(msg)))

    def _on_stamped(self, msg: TwistStampedMsg) -> None:
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        self.samples.append((stamp, _twist(msg.twist)))

    def connected(self) -> bool:
        """True once EasyNav's velocity publisher is matched."""
        return self.subscription.get_publisher_count() > 0

    def between(self, start: float, end: float = float("inf")) -> list[tuple[float, Twist]]:
        """Samples with ``start <= time < end``."""
        return [(t, tw) for t, tw in self.samples if start <= t < end]

    def last(self) -> Twist | None:
        """The last command received (None before any)."""
        return self.samples[-1][1] if self.samples else None
