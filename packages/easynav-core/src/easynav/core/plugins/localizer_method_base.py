"""LocalizerMethodBase: plugins that estimate the robot pose."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins.declarations import Topic
from easynav.core.plugins.method_base import MethodBase
from easynav.core.plugins.plugin_context import PluginContext
from easynav.core.tf import get_tf_buffer
from easynav.core.types import Header, Odometry

#: Topic every localizer listens to for a pose to reset to (as in the original EasyNav), relative.
INITIAL_POSE_TOPIC = "initialpose"


class LocalizerMethodBase(MethodBase):
    """A localizer: ``update_rt`` predicts from odometry (RT loop, at ``rt_freq`` or triggered),
    ``update`` corrects against the map (non-RT loop, at ``freq``). Both write ``robot_pose``
    (an :class:`Odometry`: pose in the map frame, child the robot footprint frame, stamp of the
    odometry used) and the localizer broadcasts ``map → odom``.

    Every localizer accepts ``initialpose`` (geometry_msgs/PoseWithCovarianceStamped, relative,
    depth 10), as in the original EasyNav, through this base: when hosted by a node,
    :meth:`initialize` subscribes it on the host node; a message in the map frame (or with an empty
    frame) whose pose and covariance are finite reaches :meth:`on_initial_pose` as an
    :class:`Odometry` in the map frame; anything else is logged and ignored. By default
    :meth:`on_initial_pose` continues from that pose as from a previous localizer's
    (:meth:`on_last_known_pose`).

    Thread contract: ``update_rt`` in the RT thread, ``update`` in the non-RT thread;
    ``on_initial_pose`` in the host node's executor (the non-RT loop); ``initialize`` and
    :meth:`cleanup` in the configuring thread. Exceptions: as :class:`MethodBase`; a malformed
    ``initialpose`` never raises (it is logged and ignored).
    """

    HAS_RT_UPDATE = True
    HAS_UPDATE = True
    #: Every localizer's subscription (a subclass listing its own topics keeps this one).
    TOPICS = (
        Topic(INITIAL_POSE_TOPIC, "geometry_msgs/msg/PoseWithCovarianceStamped", "sub",
              description="a pose to reset to (map frame)"),
    )

    def __init__(self) -> None:
        super().__init__()
        self._initial_pose_subscription: Any = None
        self._initial_pose_node: Any = None

    def update_rt(self, nav_state: NavState) -> None:
        """Predict. RT thread."""
        raise NotImplementedError

    def update(self, nav_state: NavState) -> None:
        """Correct. Non-RT thread."""
        raise NotImplementedError

    def on_last_known_pose(self, pose: Odometry) -> None:
        """Called once, before the first cycle of a new instance, with the valid ``robot_pose``
        left by the previous localizer (of any type). Default: ignore it.
        """

    def on_initial_pose(self, pose: Odometry) -> None:
        """Reset the estimate to ``pose`` (map frame, with the message's covariance), received
        on ``initialpose``. Default: :meth:`on_last_known_pose` (a localizer that can continue
        from a known pose can be reset to one). Host node's executor (non-RT side)."""
        self.on_last_known_pose(pose)

    # -- lifecycle ---------------------------------------------------------------------------
    def initialize(self, context: PluginContext, plugin_name: str) -> None:
        """:meth:`MethodBase.initialize`, then subscribe ``initialpose`` on the host node."""
        self._destroy_initial_pose_subscription()
        super().initialize(context, plugin_name)
        node = context.node
        if node is not None:
            from geometry_msgs.msg import PoseWithCovarianceStamped

            self._initial_pose_subscription = node.create_subscription(
                PoseWithCovarianceStamped, INITIAL_POSE_TOPIC, self.handle_initial_pose_msg, 10
            )
            self._initial_pose_node = node

    def cleanup(self) -> None:
        """:meth:`MethodBase.cleanup`, then drop the ``initialpose`` subscription."""
        try:
            super().cleanup()
        finally:
            self._destroy_initial_pose_subscription()

    def _destroy_initial_pose_subscription(self) -> None:
        subscription, self._initial_pose_subscription = self._initial_pose_subscription, None
        node, self._initial_pose_node = self._initial_pose_node, None
        if subscription is not None and node is not None:
            node.destroy_subscription(subscription)

    # -- initialpose -------------------------------------------------------------------------
    def handle_initial_pose_msg(self, msg: Any) -> None:
        """The ``initialpose`` callback: check the message, then :meth:`on_initial_pose`.

        Ignored (a warning naming the reason): a frame that is neither empty nor the map frame,
        a non-finite pose or covariance. Exceptions from :meth:`on_initial_pose` are logged, not
        raised (they would end the executor's spin).
        """
        from easynav.core.ros.converters import pose_from_msg, time_from_msg

        alias = self.plugin_name
        map_frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        frame = msg.header.frame_id
        if frame and frame.lstrip("/") != map_frame:
            self.logger.warning(
                f"{alias}: initialpose in frame '{frame}' ignored: expected '{map_frame}'"
            )
            return
        pose = pose_from_msg(msg.pose.pose)
        if not pose.is_finite():
            self.logger.warning(f"{alias}: non-finite initialpose ignored")
            return
        covariance = np.array(msg.pose.covariance, dtype=float).reshape(6, 6)
        if not np.all(np.isfinite(covariance)):
            self.logger.warning(f"{alias}: initialpose covariance not finite: ignored")
            return
        stamp = time_from_msg(msg.header.stamp)
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        odometry = Odometry(
            header=Header(stamp if stamp > 0.0 else self.now(), map_frame),
            child_frame_id=tf_info.robot_footprint_frame,
            pose=pose,
            pose_covariance=covariance,
        )
        self.logger.info(
            f"{alias}: initialpose ({pose.x:.3f}, {pose.y:.3f}, {pose.yaw:.3f}) in {map_frame}"
        )
        try:
            self.on_initial_pose(odometry)
        except Exception as exc:  # a callback must not end the executor's spin
            self.logger.error(f"{alias}: on_initial_pose raised {type(exc).__name__}: {exc}")
