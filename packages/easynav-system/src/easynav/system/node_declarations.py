"""The parameters of EasyNav's own nodes, declared once as data (no ROS needed to read them).

controller_node (robot_limits, the velocity output), system_node (cycles, frames, robot_geometry,
goal manager) and system_node's safety.* group. The nodes read them with ``read_parameters``;
``easynav check`` and the README tables use the same declarations.
"""

from __future__ import annotations

from easynav.core.plugins.declarations import Param
from easynav.core.robot import DEFAULT_ROBOT_LIMITS
from easynav.system.colision_checker import COLISION_CHECKER_PARAMETERS
from easynav.system.goals.goal_manager_params import GOAL_MANAGER_PARAMETERS

_LIMIT_DESCRIPTIONS = {
    "max_linear_vel": ("forward speed limit", "m/s"),
    "min_linear_vel": ("reverse speed limit (<= 0; 0: never reverse)", "m/s"),
    "max_angular_vel": ("turn rate limit (either direction)", "rad/s"),
    "max_linear_acc": ("linear acceleration limit", "m/s²"),
    "max_linear_decel": ("linear deceleration limit", "m/s²"),
    "max_angular_acc": ("angular acceleration limit", "rad/s²"),
    "max_angular_decel": ("angular deceleration limit", "rad/s²"),
}


def _limit_param(name: str, default: float) -> Param:
    description, unit = _LIMIT_DESCRIPTIONS[name]
    if name == "min_linear_vel":
        return Param(f"robot_limits.{name}", default, description, unit, le=0.0)
    if name.endswith("_vel"):
        return Param(f"robot_limits.{name}", default, description, unit, ge=0.0)
    return Param(f"robot_limits.{name}", default, description, unit, gt=0.0)


#: controller_node's own parameters.
CONTROLLER_NODE_PARAMETERS = (
    *(_limit_param(name, default) for name, default in DEFAULT_ROBOT_LIMITS.items()),
    Param("cmd_timeout", 0.5, "a controller command older than this brakes to zero (0: off)",
          "s", ge=0.0),
    Param("cmd_vel_keepalive_period", 0.0,
          "republish the last command at this period, with a QoS deadline (0: off)", "s",
          ge=0.0, dynamic=False),
    Param("use_cmd_vel_stamped", False, "publish TwistStamped on cmd_vel_stamped", dynamic=False),
    # The controller base's collision check (the original's names, one "l").
    *COLISION_CHECKER_PARAMETERS,
)



#: system_node's own parameters (names and defaults of the original's system_node); the goal
#: manager's follow.
SYSTEM_PARAMETERS: tuple[Param, ...] = (
    Param("use_real_time", True, "RT loop at SCHED_FIFO priority when allowed", dynamic=False),
    Param("rt_freq", 200.0, "frequency of the RT cycle", "Hz", gt=0.0, dynamic=False),
    Param("freq", 200.0, "frequency of the non-RT cycle", "Hz", gt=0.0, dynamic=False),
    Param("spin_time_rt", 0.001, "time the RT loop spins its executor per cycle", "s", ge=0.0,
          dynamic=False),
    Param("spin_time_nort", 0.001, "time the non-RT loop spins its executor per cycle", "s",
          ge=0.0, dynamic=False),
    Param("tf_prefix", "", "prefix of every frame name (multi-robot)", dynamic=False),
    Param("map_frame", "map", "the map frame", dynamic=False),
    Param("odom_frame", "odom", "the odometry frame", dynamic=False),
    Param("robot_frame", "base_link", "the robot frame", dynamic=False),
    Param("robot_footprint_frame", "base_footprint", "the robot's footprint frame",
          dynamic=False),
    Param("world_frame", "earth", "the world frame", dynamic=False),
    Param("robot_geometry.radius", 0.3, "circumscribed radius of the robot", "m", ge=0.0,
          dynamic=False),
    Param("robot_geometry.inscribed_radius", 0.3,
          "largest circle inside the robot (default: robot_geometry.radius)", "m", ge=0.0,
          dynamic=False),
    Param("robot_geometry.height", 0.5, "top of the robot above the robot frame", "m", ge=0.0,
          dynamic=False),
    *GOAL_MANAGER_PARAMETERS,
)

SYSTEM_PARAMETERS_BY_NAME = {param.name: param for param in SYSTEM_PARAMETERS}


#: safety.* parameters of system_node: the safety mode and the checks it enables (heartbeat,
#: RT monitor, safety channel, pose age, memory locking). Runtime changes go through the
#: frozen-configuration guard.
SAFETY_PARAMETERS: tuple[Param, ...] = (
    Param("safety.mode", False, "safety mode: frozen configuration, fail-stop on RT overruns"),
    Param("safety.lock_memory", False, "lock the process memory (mlockall) before activating"),
    Param("safety.plc_limits.max_linear_vel", 0.0,
          "the safety channel's linear speed limit, checked against robot_limits (0: not given)",
          "m/s", ge=0.0),
    Param("safety.plc_limits.max_angular_vel", 0.0,
          "the safety channel's turn rate limit (0: not given)", "rad/s", ge=0.0),
    Param("safety.heartbeat.period", 0.0, "period of easynav_heartbeat (0: off)", "s", ge=0.0),
    Param("safety.rt_monitor.max_period_factor", 2.0,
          "an RT cycle longer than this many periods is late", gt=1.0),
    Param("safety.rt_monitor.max_late_cycles", 10,
          "late RT cycles in a row before the monitor's ERROR", ge=1),
    Param("safety.status.timeout", 0.0,
          "the safety channel's state is stale after this long (0: not read)", "s", ge=0.0),
    Param("safety.max_pose_age", 1.0, "oldest usable robot_pose (0: off)", "s", ge=0.0),
)
