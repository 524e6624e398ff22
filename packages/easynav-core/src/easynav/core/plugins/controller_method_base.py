"""ControllerMethodBase: plugins that turn a path into velocity commands."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins.method_base import MethodBase
from easynav.core.robot import RobotLimits


class ControllerMethodBase(MethodBase):
    """A controller: ``update_rt`` reads ``path``, ``robot_pose``, perceptions and
    ``goal_tolerance.*`` from NavState and writes ``cmd_vel`` (a :class:`TwistStamped`, with a new
    stamp on every new command: the command guard ignores repeated ones).

    Runs in the RT loop when due (``rt_freq``) or triggered by new perceptions / a localizer run.
    """

    HAS_RT_UPDATE = True

    def update_rt(self, nav_state: NavState) -> None:
        """Compute the command. RT thread. Exceptions are contained (the robot brakes)."""
        raise NotImplementedError

    def get_robot_limits(self) -> RobotLimits:
        """The limits in force: robot_limits, cut down by a safely limited speed if any."""
        return self.context.robot_limits()
