"""ControllerMethodBase: plugins that turn a path into velocity commands."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import ClassVar

from easynav.core.nav_state import NavState
from easynav.core.plugins.declarations import Param
from easynav.core.plugins.method_base import MethodBase
from easynav.core.robot import RobotLimits


class ControllerMethodBase(MethodBase):
    """A controller: ``update_rt`` reads ``path``, ``robot_pose``, perceptions and
    ``goal_tolerance.*`` from NavState and writes ``cmd_vel`` (a :class:`TwistStamped`, with a new
    stamp on every new command: the command guard ignores repeated ones).

    Runs in the RT loop when due (``rt_freq``) or triggered by new perceptions / a localizer run.
    """

    HAS_RT_UPDATE = True

    #: The original controllers' own limits, deprecated in favour of
    #: ``controller_node.robot_limits.*``: unset (NaN) by default; set, controller_node applies
    #: each to the robot_limits field it stands for where the user did not set that field
    #: (explicit robot_limits and runtime changes win). Controllers use only
    #: :meth:`get_robot_limits`.
    DEPRECATED_PARAMETERS = (
        Param("max_linear_speed", math.nan,
              "deprecated: controller_node robot_limits.max_linear_vel", "m/s", ge=0.0,
              allow_nan=True, dynamic=False),
        Param("max_angular_speed", math.nan,
              "deprecated: controller_node robot_limits.max_angular_vel", "rad/s", ge=0.0,
              allow_nan=True, dynamic=False),
        Param("max_linear_acc", math.nan,
              "deprecated: controller_node robot_limits.max_linear_acc", "m/s²", ge=0.0,
              allow_nan=True, dynamic=False),
        Param("max_angular_acc", math.nan,
              "deprecated: controller_node robot_limits.max_angular_acc", "rad/s²", ge=0.0,
              allow_nan=True, dynamic=False),
    )

    #: Deprecated limits a controller's original named otherwise, beyond those four:
    #: ``{parameter: RobotLimits field}`` (MPC: ``max_linear_velocity``; VFF: ``max_speed``).
    #: controller_node applies them as it applies :attr:`DEPRECATED_PARAMETERS`; the controller
    #: declares the parameters itself.
    DEPRECATED_LIMITS: ClassVar[Mapping[str, str]] = {}

    def update_rt(self, nav_state: NavState) -> None:
        """Compute the command. RT thread. Exceptions are contained (the robot brakes)."""
        raise NotImplementedError

    def get_robot_limits(self) -> RobotLimits:
        """The limits in force: robot_limits, cut down by a safely limited speed if any."""
        return self.context.robot_limits()
