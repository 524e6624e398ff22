"""The NavState keys shared between components, declared once with their types.

Each constant is a :class:`NavStateKey`: a ``str`` (so ``nav_state.get(PATH)`` and any code that
uses the plain name keep working) that also carries the value's type and a description, which
``easynav plugins --describe`` and the README tables show. A plugin lists the keys it reads and
writes in ``READS`` / ``WRITES`` and uses these constants instead of string literals.
"""

from __future__ import annotations


class NavStateKey(str):
    """A NavState key: its name (the ``str`` itself), the type of its value, a description."""

    value_type: str
    description: str

    def __new__(cls, name: str, value_type: str | type = "", description: str = "") -> NavStateKey:
        key = super().__new__(cls, name)
        key.value_type = value_type if isinstance(value_type, str) else value_type.__name__
        key.description = description
        return key

    def __reduce__(self):
        return (NavStateKey, (str(self), self.value_type, self.description))


ROBOT_POSE = NavStateKey(
    "robot_pose",
    "Odometry",
    "the localizer's pose in the map frame, covariance and measured twist.",
)

GOALS = NavStateKey(
    "goals", "Goals", "the waypoints still to visit; empty when idle (goal manager)."
)

NAVIGATION_STATE = NavStateKey("navigation_state", "str", '"IDLE" or "ACTIVE" (goal manager).')

NAVIGATION_PAUSED = NavStateKey(
    "navigation_paused",
    "bool",
    "a client paused the navigation; the velocity mux outputs zero (goal manager).",
)

PATH = NavStateKey("path", "Path", 'the planner\'s path; empty means "no plan".')

CMD_VEL = NavStateKey(
    "cmd_vel",
    "TwistStamped",
    "the controller's command (stamp every new one); the one published may differ.",
)

PROPOSAL_TAKEOVER = NavStateKey(
    "cmd_vel.proposal.takeover",
    "Twist",
    "the recovery system drives the robot this RT cycle (smoothed).",
)

PROPOSAL_OVERRIDE = NavStateKey(
    "cmd_vel.proposal.override",
    "Twist",
    "the recovery system's emergency command this RT cycle (published as is).",
)

SAFETY_STATUS = NavStateKey(
    "safety_status", "SafetyChannelState", "only when system_node reads the safety channel."
)

MOTION_INHIBITED = NavStateKey(
    "motion_inhibited",
    "bool",
    "in safety mode, the robot pose is not usable; the command brakes to zero.",
)

CONFIGURATION_HASH = NavStateKey(
    "configuration_hash", "str", "SHA-256 of the configuration (safety supervisor)."
)

RECONFIGURED_PARAMETERS = NavStateKey(
    "reconfigured_parameters",
    "list[str]",
    "``node/parameter`` changed through ``request_reconfigure``.",
)

GOAL_TOLERANCE_POSITION = NavStateKey(
    "goal_tolerance.position", "float", "the goal manager's position tolerance (m)."
)

GOAL_TOLERANCE_YAW = NavStateKey(
    "goal_tolerance.yaw", "float", "the goal manager's yaw tolerance (rad)."
)

GOAL_TOLERANCE_HEIGHT = NavStateKey(
    "goal_tolerance.height", "float", "the goal manager's height tolerance (m)."
)

MAP_BASE = NavStateKey(
    "map.base", "map", "the static map (the maps manager's representation: SimpleMap, Costmap2D)."
)

MAP = NavStateKey("map", "map", "the map with live obstacles (SimpleMap, Costmap2D).")

MAP_TIME = NavStateKey("map_time", "float", "node-clock time of the last map update (s).")

CONTROL_OWNER = NavStateKey(
    "control_owner",
    "str",
    '"controller", or "recovery:<alias>" while a recovery mitigation drives the robot.',
)

DIAGNOSTICS_PATH = NavStateKey(
    "diagnostics.path", "DiagnosticStatus", "the planner's diagnostic: OK, or WARN saying why."
)

SPEED_LIMIT = NavStateKey(
    "speed_limit",
    "float",
    "the speed zone's limit at the robot's position, a fraction (0, 1] of the limits in force "
    "(1.0: no zone); the velocity output cuts the linear and angular limits by it (SpeedFilter).",
)
