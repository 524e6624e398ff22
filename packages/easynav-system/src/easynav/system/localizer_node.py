"""LocalizerNode: hosts the localizer (RT prediction, non-RT correction)."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.core.nav_state_keys import ROBOT_POSE
from easynav.core.plugins.localizer_method_base import INITIAL_POSE_TOPIC
from easynav.core.plugins.plugin_kinds import LOCALIZER
from easynav.core.types import Odometry
from easynav.system.component_node import ComponentNode
from easynav.system.ros.converters import pose_from_msg, time_from_msg


class LocalizerNode(ComponentNode):
    """localizer_node: ``localizer_types`` (at most one), ``<alias>.*``.

    A new localizer instance gets the valid ``robot_pose`` left in NavState by the previous one,
    of any type, through ``on_last_known_pose`` before its first cycle. While a localizer is
    loaded the node subscribes ``initialpose`` (PoseWithCovarianceStamped, relative, depth 10)
    and hands each message to the localizer's ``handle_initial_pose``, which checks it.

    Thread contract: ``cycle_rt`` in the RT thread, ``cycle`` and the ``initialpose`` callback
    in the non-RT thread.
    """

    KIND = LOCALIZER
    TYPES_PARAMETER = "localizer_types"
    MAX_PLUGINS = 1

    def __init__(self, namespace, system, **kwargs):
        super().__init__("localizer_node", namespace, system, **kwargs)
        self._initial_pose_subscription: Any = None

    def after_plugins_loaded(self) -> None:
        if self.plugins and self._initial_pose_subscription is None:
            from geometry_msgs.msg import PoseWithCovarianceStamped

            self._initial_pose_subscription = self.create_subscription(
                PoseWithCovarianceStamped, INITIAL_POSE_TOPIC, self._on_initial_pose, 10
            )
        if not self.nav_state.has(ROBOT_POSE):
            return
        pose = self.nav_state.get_safe(ROBOT_POSE, Odometry)
        if pose.is_finite():
            for lp in self.plugins:
                lp.plugin.on_last_known_pose(pose)

    def cleanup_node(self) -> None:
        super().cleanup_node()
        subscription, self._initial_pose_subscription = self._initial_pose_subscription, None
        if subscription is not None:
            self.destroy_subscription(subscription)

    def _on_initial_pose(self, msg: Any) -> None:
        for lp in self.plugins:
            lp.plugin.handle_initial_pose(*initial_pose_values(msg))

    def cycle_rt(self, trigger: bool) -> bool:
        """Predict when due or triggered; True when the localizer ran. RT thread."""
        if not self.active:
            return False
        return bool(self.run_scheduled(rt=True, force=trigger))

    def cycle(self) -> None:
        """Correct when due. Non-RT thread."""
        if self.active:
            self.run_scheduled(rt=False)


def initial_pose_values(msg: Any) -> tuple[str, float, Any, np.ndarray]:
    """A PoseWithCovarianceStamped as ``handle_initial_pose`` takes it: frame, stamp (seconds),
    pose and 6×6 covariance (unchecked: the localizer's base checks them)."""
    covariance = np.array(msg.pose.covariance, dtype=float).reshape(6, 6)
    return (msg.header.frame_id, time_from_msg(msg.header.stamp), pose_from_msg(msg.pose.pose),
            covariance)
