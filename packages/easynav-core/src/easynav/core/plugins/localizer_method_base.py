"""LocalizerMethodBase: plugins that estimate the robot pose."""

from __future__ import annotations

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins.declarations import Topic
from easynav.core.plugins.method_base import MethodBase
from easynav.core.types import Header, Odometry, Pose

#: Topic every localizer listens to for a pose to reset to (as in the original EasyNav), relative.
INITIAL_POSE_TOPIC = "initialpose"


class LocalizerMethodBase(MethodBase):
    """A localizer: ``update_rt`` predicts from odometry (RT loop, at ``rt_freq`` or triggered),
    ``update`` corrects against the map (non-RT loop, at ``freq``). Both write ``robot_pose``
    (an :class:`Odometry`: pose in the map frame, child the robot footprint frame, stamp of the
    odometry used) and the localizer broadcasts ``map → odom``.

    Every localizer accepts ``initialpose`` (geometry_msgs/PoseWithCovarianceStamped, relative,
    depth 10), as in the original EasyNav: the runtime's localizer node subscribes it and hands
    each message, as plain values, to :meth:`handle_initial_pose`, which checks it (map frame or
    empty, finite pose and covariance) and calls :meth:`on_initial_pose` with an
    :class:`Odometry` in the map frame; anything else is logged and ignored. By default
    :meth:`on_initial_pose` continues from that pose as from a previous localizer's
    (:meth:`on_last_known_pose`).

    Thread contract: ``update_rt`` in the RT thread, ``update`` in the non-RT thread;
    :meth:`handle_initial_pose` and ``on_initial_pose`` in the non-RT loop (the host node's
    executor). Exceptions: as :class:`MethodBase`; a malformed ``initialpose`` never raises (it
    is logged and ignored).
    """

    HAS_RT_UPDATE = True
    HAS_UPDATE = True
    #: Every localizer's subscription (a subclass listing its own topics keeps this one).
    TOPICS = (
        Topic(INITIAL_POSE_TOPIC, "geometry_msgs/msg/PoseWithCovarianceStamped", "sub",
              description="a pose to reset to (map frame)"),
    )

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

    # -- initialpose -------------------------------------------------------------------------
    def handle_initial_pose(
        self, frame: str, stamp: float, pose: Pose, covariance: np.ndarray
    ) -> None:
        """An ``initialpose`` received by the host: check it, then :meth:`on_initial_pose`.

        ``frame`` and ``stamp`` (seconds; 0 means now) are the message header's, ``covariance``
        its 6×6 pose covariance. Ignored (a warning naming the reason): a frame that is neither
        empty nor the map frame, a non-finite pose or covariance. Exceptions from
        :meth:`on_initial_pose` are logged, not raised (they would end the executor's spin).
        """
        alias = self.plugin_name
        tf_info = self.get_tf_info()
        map_frame = tf_info.map_frame
        if frame and frame.lstrip("/") != map_frame:
            self.logger.warning(
                f"{alias}: initialpose in frame '{frame}' ignored: expected '{map_frame}'"
            )
            return
        if not pose.is_finite():
            self.logger.warning(f"{alias}: non-finite initialpose ignored")
            return
        covariance = np.asarray(covariance, dtype=float).reshape(6, 6)
        if not np.all(np.isfinite(covariance)):
            self.logger.warning(f"{alias}: initialpose covariance not finite: ignored")
            return
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
