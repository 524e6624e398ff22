"""GoalManagerRos: the goal manager's topics on system_node."""

from __future__ import annotations

import threading
from typing import Any

from easynav_interfaces.msg import GoalManagerInfo as GoalManagerInfoMsg
from easynav_interfaces.msg import NavigationControl as NavigationControlMsg
from geometry_msgs.msg import PoseStamped as PoseStampedMsg

from easynav.system.goals.goal_manager import GoalManager
from easynav.system.goals.navigation_control import NavigationControl
from easynav.system.goals.protocol import (
    CONTROL_TOPIC,
    GOAL_POSE_TOPIC,
    MANAGER_INFO_TOPIC,
    SYSTEM_USER_ID,
)
from easynav.system.goals.ros_conversion import (
    goal_manager_info_to_msg,
    goal_topics_qos,
    navigation_control_from_msg,
    navigation_control_to_msg,
)
from easynav.system.ros.converters import pose_stamped_from_msg


class GoalManagerRos:
    """Connects a :class:`GoalManager` to ROS on the given node (system_node).

    Creates, with relative names (the node's namespace applies) and reliable / keep-last 100 /
    volatile QoS: a publisher and a subscription on ``easynav_control``
    (easynav_interfaces/NavigationControl), a subscription on ``goal_pose``
    (geometry_msgs/PoseStamped) and a publisher on ``easynav_manager_info``
    (easynav_interfaces/GoalManagerInfo). Replies to incoming messages are published from the
    subscription callback; :meth:`update` publishes the mission's own messages and the info.

    Thread contract: the subscriptions belong to ``callback_group`` (the node's default group
    when None) and must be spun by the non-RT loop thread, which also calls :meth:`update`.
    Every method serialises the goal manager call and its publication under one lock, so the
    order on the topic is the order of the decisions even when :meth:`abort_mission` comes from
    another thread. A failure while handling one incoming message is logged with the message and
    does not stop the loop; :meth:`update` lets exceptions through.
    """

    def __init__(self, node: Any, goal_manager: GoalManager, callback_group: Any = None) -> None:
        self._node = node
        self._goal_manager = goal_manager
        self._lock = threading.Lock()
        qos = goal_topics_qos()
        self._control_pub = node.create_publisher(NavigationControlMsg, CONTROL_TOPIC, qos)
        self._info_pub = node.create_publisher(GoalManagerInfoMsg, MANAGER_INFO_TOPIC, qos)
        self._control_sub = node.create_subscription(
            NavigationControlMsg, CONTROL_TOPIC, self._on_control, qos,
            callback_group=callback_group,
        )
        self._goal_pose_sub = node.create_subscription(
            PoseStampedMsg, GOAL_POSE_TOPIC, self._on_goal_pose, qos,
            callback_group=callback_group,
        )

    @property
    def goal_manager(self) -> GoalManager:
        """The logic behind the topics."""
        return self._goal_manager

    def publish(self, msgs: list[NavigationControl]) -> None:
        """Publish native messages on ``easynav_control``, in order. Any thread."""
        for msg in msgs:
            self._control_pub.publish(navigation_control_to_msg(msg))

    def update(self) -> list[NavigationControl]:
        """One non-RT cycle of the goal manager; publishes its messages (FEEDBACK, FINISHED)
        and the GoalManagerInfo due, and returns the messages. Non-RT thread.
        """
        with self._lock:
            msgs = self._goal_manager.update()
            self.publish(msgs)
            while (info := self._goal_manager.info()) is not None:
                self._info_pub.publish(goal_manager_info_to_msg(info))
            return msgs

    def abort_mission(self, reason: str) -> list[NavigationControl]:
        """End the mission with ERROR ``reason`` to its owner and publish it. Any thread."""
        with self._lock:
            msgs = self._goal_manager.abort_mission(reason)
            self.publish(msgs)
            return msgs

    def destroy(self) -> None:
        """Remove the publishers and subscriptions from the node (the goal manager and its
        mission stay). Non-RT thread, with the loop stopped.
        """
        for entity in (self._control_sub, self._goal_pose_sub):
            self._node.destroy_subscription(entity)
        for entity in (self._control_pub, self._info_pub):
            self._node.destroy_publisher(entity)

    # -- callbacks ---------------------------------------------------------------------------
    def _on_control(self, msg: NavigationControlMsg) -> None:
        if msg.user_id == SYSTEM_USER_ID:
            return  # our own replies and feedback come back on the shared topic
        try:
            with self._lock:
                self.publish(self._goal_manager.handle_control(navigation_control_from_msg(msg)))
        except Exception as exc:  # one bad message must not stop the non-RT loop
            self._node.get_logger().error(
                f"goal manager failed on a control message from '{msg.user_id}' "
                f"(type {msg.type}, seq {msg.seq}): {exc!r}"
            )

    def _on_goal_pose(self, msg: PoseStampedMsg) -> None:
        try:
            with self._lock:
                self.publish(self._goal_manager.handle_goal_pose(pose_stamped_from_msg(msg)))
        except Exception as exc:  # one bad message must not stop the non-RT loop
            self._node.get_logger().error(f"goal manager failed on a goal_pose message: {exc!r}")
