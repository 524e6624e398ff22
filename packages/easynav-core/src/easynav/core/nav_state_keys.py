"""The NavState keys shared between components (REFERENCE.md §3), in one ROS-free place."""

from __future__ import annotations

ROBOT_POSE = "robot_pose"
"""Odometry: the localizer's pose in the map frame, covariance and measured twist."""

GOALS = "goals"
"""Goals: the waypoints still to visit; empty when idle (goal manager)."""

NAVIGATION_STATE = "navigation_state"
"""str: "IDLE" or "ACTIVE" (goal manager)."""

NAVIGATION_PAUSED = "navigation_paused"
"""bool: a client paused the navigation; the velocity mux outputs zero (goal manager)."""

PATH = "path"
"""Path: the planner's path; empty means "no plan"."""

CMD_VEL = "cmd_vel"
"""TwistStamped: the controller's command (stamp every new one); the one published may differ."""

PROPOSAL_TAKEOVER = "cmd_vel.proposal.takeover"
"""Twist: the recovery system drives the robot this RT cycle (smoothed)."""

PROPOSAL_OVERRIDE = "cmd_vel.proposal.override"
"""Twist: the recovery system's emergency command this RT cycle (published as is)."""

SAFETY_STATUS = "safety_status"
"""SafetyChannelState: only when system_node reads the safety channel."""

MOTION_INHIBITED = "motion_inhibited"
"""bool: in safety mode, the robot pose is not usable; the command brakes to zero."""

CONFIGURATION_HASH = "configuration_hash"
"""str: SHA-256 of the configuration (safety supervisor)."""

RECONFIGURED_PARAMETERS = "reconfigured_parameters"
"""list[str]: ``node/parameter`` changed through ``request_reconfigure``."""
