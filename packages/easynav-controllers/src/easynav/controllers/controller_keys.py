"""NavState keys read or written by the controllers (beyond the kernel's), declared once.

The kernel declares ``path``, ``robot_pose``, ``navigation_state`` and ``cmd_vel``
(``easynav.core.nav_state_keys``); these are the costmap stack's and the goal manager's keys a
controller reads, with the names of the original, and SeReST's debug values.
"""

from __future__ import annotations

from easynav.core.nav_state_keys import NavStateKey

MAP = NavStateKey(
    "map",
    "Costmap2D",
    "the dynamic costmap (costmap maps manager), or the simple maps manager's SimpleMap (its "
    "occupied cells are lethal obstacles), or the GridmapMapsManager's GridMap (its "
    "untraversable cells are lethal obstacles).",
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

CLOSEST_OBSTACLE_DISTANCE = NavStateKey(
    "closest_obstacle_distance",
    "float",
    "distance (m) from the robot to the nearest obstacle, when a component measures it.",
)

#: SeReST's debug values (floats; the flags are ints 0/1, as in the original).
SEREST_DEBUG_KEYS = {
    name: NavStateKey(f"serest.debug.{name}", kind, text)
    for name, kind, text in (
        ("e_y", "float", "lateral error to the path (m, + left)"),
        ("e_theta", "float", "heading error to the path tangent (rad)"),
        ("kappa_hat", "float", "blended reference curvature (1/m)"),
        ("d_closest", "float", "distance to the closest obstacle (m; inf when none)"),
        ("v_safe", "float", "speed that can stop before the closest obstacle (m/s)"),
        ("v_curv", "float", "speed allowed by the curvature (m/s)"),
        ("alpha", "float", "time-scaling factor min(1, v_safe / v_ref)"),
        ("allow_reverse", "int", "1 when reversing is allowed"),
        ("dist_to_end", "float", "path length left to the end (m)"),
        ("goal.dist_xy", "float", "straight-line distance to the goal (m)"),
        ("goal.gamma_slow", "float", "slow-zone scale of the progress speed, 0..1"),
        ("goal.in_final_align", "int", "1 while turning in place to the goal yaw"),
        ("goal.arrived", "int", "1 once at the goal position and yaw"),
    )
}
