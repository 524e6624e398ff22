"""The EasyNav system the fault-injection suite runs: one Faulty plugin per component.

Every plugin works normally (``fault: none``) unless a test overrides ``<node>.<alias>.fault``.
Aliases are unique across nodes, so diagnostics are ``diagnostics.<alias>.*``.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from easynav.core.robot import RobotLimits
from easynav.system.testing.system_fixtures import system_params

#: The limits every test checks against (fast ramps keep the tests short).
LIMITS = RobotLimits(
    max_linear_vel=0.5,
    min_linear_vel=-0.2,
    max_angular_vel=1.0,
    max_linear_acc=1.0,
    max_linear_decel=1.0,
    max_angular_acc=2.0,
    max_angular_decel=2.0,
)
LINEAR_VEL = 0.3
ANGULAR_VEL = 0.4
CMD_TIMEOUT = 0.3
KEEPALIVE = 0.1
RT_FREQ = 200.0

#: ``(node, alias, plugin)`` of the four Faulty plugins.
CONTROLLER = ("controller_node", "ctrl", "easynav_controller/FaultyController")
LOCALIZER = ("localizer_node", "loc", "easynav_localizer/FaultyLocalizer")
PLANNER = ("planner_node", "plan", "easynav_planner/FaultyPlanner")
MAPS_MANAGER = ("maps_manager_node", "maps", "easynav_maps_manager/FaultyMapsManager")
ALL_PLUGINS = (CONTROLLER, LOCALIZER, PLANNER, MAPS_MANAGER)

BASE: dict[str, Any] = {
    "system_node": {"rt_freq": RT_FREQ, "freq": 50.0},
    "controller_node": {
        "controller_types": ["ctrl"],
        "ctrl": {
            "plugin": CONTROLLER[2],
            "rt_freq": 50.0,
            "linear_vel": LINEAR_VEL,
            "angular_vel": ANGULAR_VEL,
        },
        "robot_limits": dataclasses.asdict(LIMITS),
        "cmd_timeout": CMD_TIMEOUT,
        # Commands are republished at least this often, so what reaches the robot can be
        # watched even while it does not change.
        "cmd_vel_keepalive_period": KEEPALIVE,
    },
    "localizer_node": {
        "localizer_types": ["loc"],
        "loc": {"plugin": LOCALIZER[2], "rt_freq": 20.0, "freq": 5.0},
    },
    "maps_manager_node": {"map_types": ["maps"], "maps": {"plugin": MAPS_MANAGER[2], "freq": 10.0}},
    "planner_node": {"planner_types": ["plan"], "plan": {"plugin": PLANNER[2], "freq": 5.0}},
    "sensors_node": {"forget_time": 0.5},
    "recovery_node": {"recovery_manager": {"plugin": "easynav_recovery/DummyRecoveryManager"}},
}


def faulty_system(**overrides: Any) -> dict[str, Any]:
    """The params document of :data:`BASE` with ``overrides`` (dotted paths, as
    :func:`system_params`: ``faulty_system(**{"controller_node.ctrl.fault": "nan"})``).
    """
    return system_params(BASE, **overrides)


def inject(plugin: tuple[str, str, str], fault: str, fault_after: int = 0, **params: Any):
    """Overrides that make ``plugin`` inject ``fault`` after ``fault_after`` updates."""
    node, alias, _ = plugin
    values = {"fault": fault, "fault_after": fault_after, **params}
    return {f"{node}.{alias}.{name}": value for name, value in values.items()}


