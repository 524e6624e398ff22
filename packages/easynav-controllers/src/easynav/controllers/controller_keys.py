"""NavState keys read by the Regulated Pure Pursuit and MPPI controllers (beyond the kernel's).

The kernel declares ``path``, ``robot_pose``, ``navigation_state`` and ``cmd_vel``
(``easynav.core.nav_state_keys``); these are the costmap stack's and the goal manager's keys a
controller reads, with the names of the original.
"""

from __future__ import annotations

from easynav.core.nav_state_keys import NavStateKey

MAP = NavStateKey(
    "map",
    "Costmap2D",
    "the dynamic costmap (costmap maps manager); absent: no obstacle terms.",
)

GOAL_TOLERANCE_POSITION = NavStateKey(
    "goal_tolerance.position",
    "float",
    "distance (m) to the last path pose within which the goal is reached (goal manager).",
)

GOAL_TOLERANCE_YAW = NavStateKey(
    "goal_tolerance.yaw",
    "float",
    "yaw error (rad) to the last path pose within which the goal is reached (goal manager).",
)
