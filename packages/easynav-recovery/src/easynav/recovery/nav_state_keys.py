"""NavState keys the recovery systems read and write (REFERENCE.md §3).

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
)

AMCL_COVARIANCE_TRACE = "localizer.amcl.covariance_trace"
"""float: var x + var y + var yaw of the AMCL particle cloud."""

SENSORS_DIAGNOSTIC = "diagnostics.sensors"
"""DiagnosticStatus of sensors_node; ``values["no_data"]`` lists the sensors without data yet."""


CONTROL_OWNER = "control_owner"
"""str: "controller", or "recovery:<alias>" while a mitigation drives the robot (the
DiagnosticRecoveryManager writes it; evaluators that watch the controller read it)."""

CONTROLLER_OWNS_CONTROL = "controller"
"""Value of :data:`CONTROL_OWNER` when no mitigation drives the robot."""
