"""LocalizerNode: hosts the localizer (RT prediction, non-RT correction)."""

from __future__ import annotations

from collections.abc import Callable, Iterable
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
            self._initial_pose_subscription = subscribe_initial_pose(
                self, lambda: [lp.plugin for lp in self.plugins]
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

    def cycle_rt(self, trigger: bool) -> bool:
        """Predict when due or triggered; True when the localizer ran. RT thread."""
        if not self.active:
            return False
        return bool(self.run_scheduled(rt=True, force=trigger))

    def cycle(self) -> None:
        """Correct when due. Non-RT thread."""
        if self.active:
            self.run_scheduled(rt=False)


def subscribe_initial_pose(node: Any, localizers: Callable[[], Iterable[Any]]) -> Any:
    """Subscribe ``initialpose`` (PoseWithCovarianceStamped, relative, depth 10) on ``node``;
    each message goes to the ``handle_initial_pose`` of every localizer ``localizers()`` gives
    (which checks it and never raises). Returns the subscription, for the caller to destroy.

    localizer_node does this for its localizer; a script or a test that hosts a localizer on a
    node of its own calls it the same way.
    """
    from geometry_msgs.msg import PoseWithCovarianceStamped

    def deliver(msg: Any) -> None:
        values = initial_pose_values(msg)
        for localizer in localizers():
            localizer.handle_initial_pose(*values)

    return node.create_subscription(PoseWithCovarianceStamped, INITIAL_POSE_TOPIC, deliver, 10)


def initial_pose_values(msg: Any) -> tuple[str, float, Any, np.ndarray]:
    """A PoseWithCovarianceStamped as ``handle_initial_pose`` takes it: frame, stamp (seconds),
    pose and 6×6 covariance (unchecked: the localizer's base checks them)."""
    covariance = np.array(msg.pose.covariance, dtype=float).reshape(6, 6)
    return (msg.header.frame_id, time_from_msg(msg.header.stamp), pose_from_msg(msg.pose.pose),
            covariance)
