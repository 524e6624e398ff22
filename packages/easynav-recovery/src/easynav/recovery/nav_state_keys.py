"""NavState keys the recovery systems read and write, under the original EasyNav's names (the
AMCL covariance trace, the sensors diagnostic, the control owner).

The keys shared by every component come from ``easynav.core.nav_state_keys``.
"""

from __future__ import annotations

from easynav.core.nav_state_keys import (  # noqa: F401  (re-exported)
    CMD_VEL,
    GOALS,
    NAVIGATION_PAUSED,
    NAVIGATION_STATE,
    PATH,
    PROPOSAL_OVERRIDE,
    PROPOSAL_TAKEOVER,
    RECONFIGURED_PARAMETERS,
    ROBOT_POSE,
    SAFETY_STATUS,
    NavStateKey,
)
from easynav.core.nav_state_keys import CONTROL_OWNER as CORE_CONTROL_OWNER

AMCL_COVARIANCE_TRACE = NavStateKey(
    "localizer.amcl.covariance_trace", "float", "var x + var y + var yaw of the particle cloud."
)

SENSORS_DIAGNOSTIC = NavStateKey(
    "diagnostics.sensors",
    "DiagnosticStatus",
    'sensors_node\'s diagnostic; values["no_data"] lists the sensors without data yet.',
)

#: "controller", or "recovery:<alias>" while a mitigation drives the robot (the
#: DiagnosticRecoveryManager writes it; evaluators that watch the controller read it).
CONTROL_OWNER = CORE_CONTROL_OWNER

CONTROLLER_OWNS_CONTROL = "controller"
"""Value of :data:`CONTROL_OWNER` when no mitigation drives the robot."""
