"""NavState keys the recovery systems read and write (REFERENCE.md §3)."""

from __future__ import annotations

ROBOT_POSE = "robot_pose"
"""Odometry: the localizer's pose (map frame), covariance and measured twist."""

CMD_VEL = "cmd_vel"
"""TwistStamped: the controller's command (its proposal; the one published may differ)."""

PATH = "path"
"""Path: the planner's path; empty means "no plan"."""

GOALS = "goals"
"""Goals: the waypoints of the mission; empty when idle."""

NAVIGATION_STATE = "navigation_state"
"""str: "IDLE" or "ACTIVE"."""

NAVIGATION_PAUSED = "navigation_paused"
"""bool: a client paused the navigation (the velocity mux outputs zero)."""

SAFETY_STATUS = "safety_status"
"""SafetyChannelState: present only when system_node reads the safety channel."""

AMCL_COVARIANCE_TRACE = "localizer.amcl.covariance_trace"
"""float: var x + var y + var yaw of the AMCL particle cloud."""

SENSORS_DIAGNOSTIC = "diagnostics.sensors"
"""DiagnosticStatus of sensors_node; ``values["no_data"]`` lists the sensors without data yet."""

RECONFIGURED_PARAMETERS = "reconfigured_parameters"
"""list[str]: ``node/parameter`` changed through ``request_reconfigure`` (system_node writes)."""

PROPOSAL_TAKEOVER = "cmd_vel.proposal.takeover"
"""Twist: the recovery system drives the robot this RT cycle (recovery_node writes)."""

PROPOSAL_OVERRIDE = "cmd_vel.proposal.override"
"""Twist: emergency command of this RT cycle, published as is (recovery_node writes)."""

CONTROL_OWNER = "control_owner"
"""str: "controller", or "recovery:<alias>" while a mitigation drives the robot (the
DiagnosticRecoveryManager writes it; evaluators that watch the controller read it)."""

CONTROLLER_OWNS_CONTROL = "controller"
"""Value of :data:`CONTROL_OWNER` when no mitigation drives the robot."""
