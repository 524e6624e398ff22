"""LocalizerMethodBase: plugins that estimate the robot pose."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins.method_base import MethodBase
from easynav.core.types import Odometry


class LocalizerMethodBase(MethodBase):
    """A localizer: ``update_rt`` predicts from odometry (RT loop, at ``rt_freq`` or triggered),
    ``update`` corrects against the map (non-RT loop, at ``freq``). Both write ``robot_pose``
    (an :class:`Odometry`: pose in the map frame, child the robot footprint frame, stamp of the
    odometry used) and the localizer broadcasts ``map → odom``.
    """

    HAS_RT_UPDATE = True
    HAS_UPDATE = True

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
