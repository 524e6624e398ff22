"""A small ROS test bed for the goal topics: one context, one SingleThreadedExecutor spun by the
test itself, a goal manager on a ``system_node`` whose ``update`` runs as the non-RT loop would,
raw publishers and recorders.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import rclpy
from easynav_interfaces.msg import GoalManagerInfo as GoalManagerInfoMsg
from easynav_interfaces.msg import NavigationControl as NavigationControlMsg
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor

from easynav.core.nav_state import NavState
from easynav.system.goals import GoalManager, GoalManagerParams, NavigationControl
from easynav.system.goals.goal_manager_client import GoalManagerClient
from easynav.system.goals.goal_manager_ros import GoalManagerRos
from easynav.system.goals.ros_conversion import (
    goal_manager_info_from_msg,
    goal_topics_qos,
    navigation_control_from_msg,
    navigation_control_to_msg,
)


class SystemUnderTest:
    """A goal manager on its own node, as system_node hosts it."""

    def __init__(self, bed: RosTestbed, params: GoalManagerParams, namespace: str) -> None:
        self.bed = bed
        self.node = bed.node("system_node", namespace)
        self.nav_state = NavState()
        self.manager = GoalManager(self.nav_state, params, time.monotonic)
        self.ros = GoalManagerRos(self.node, self.manager)

    def reconfigure(self, params: GoalManagerParams) -> None:
        """What system_node does on cleanup + configure: topics go, the manager stays."""
        self.ros.destroy()
        self.manager.set_params(params)
        self.ros = GoalManagerRos(self.node, self.manager)


class Recorder:
    """Every message on ``easynav_control`` (native) and ``easynav_manager_info`` seen by a node."""

    def __init__(self, node) -> None:
        self.controls: list[NavigationControl] = []
        self.infos = []
        qos = goal_topics_qos()
        node.create_subscription(
            NavigationControlMsg, "easynav_control",
            lambda m: self.controls.append(navigation_control_from_msg(m)), qos,
        )
        node.create_subscription(
            GoalManagerInfoMsg, "easynav_manager_info",
            lambda m: self.infos.append(goal_manager_info_from_msg(m)), qos,
        )
        self._publisher = node.create_publisher(NavigationControlMsg, "easynav_control", qos)

    def from_system(self) -> list[NavigationControl]:
        return [m for m in self.controls if m.user_id == "easynav_system"]

    def replies_to(self, user: str) -> list[NavigationControl]:
        return [m for m in self.from_system() if m.nav_current_user_id == user]

    def send(self, msg: NavigationControl) -> None:
        """Publish a raw message, as a foreign tool would."""
        self._publisher.publish(navigation_control_to_msg(msg))

    def matched(self) -> bool:
        return self._publisher.get_subscription_count() > 0


class RosTestbed:
    """Owns one initialised context and its executor; :meth:`close` shuts them down in order."""

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.nodes = []
        self.systems: list[SystemUnderTest] = []

    def node(self, name: str, namespace: str = ""):
        node = rclpy.create_node(name, namespace=namespace, context=self.context)
        self.executor.add_node(node)
        self.nodes.append(node)
        return node

    def system(self, params: GoalManagerParams | None = None, namespace: str = ""):
        system = SystemUnderTest(self, params or GoalManagerParams(), namespace)
        self.systems.append(system)
        return system

    def client(self, name: str, namespace: str = "") -> GoalManagerClient:
        return GoalManagerClient(self.node(name, namespace))

    def spin_until(self, done: Callable[[], bool], timeout: float = 3.0) -> bool:
        """Spin (and run every system's non-RT ``update``) until ``done()`` or the timeout."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.001)
            for system in self.systems:
                system.ros.update()
            if done():
                return True
        return False

    def spin_for(self, seconds: float) -> None:
        self.spin_until(lambda: False, timeout=seconds)

    def close(self) -> None:
        self.executor.shutdown()
        for node in self.nodes:
            node.destroy_node()
        rclpy.shutdown(context=self.context)
