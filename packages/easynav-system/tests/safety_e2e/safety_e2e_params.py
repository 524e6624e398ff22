"""Params documents of the end-to-end safety suite: an EasyNav whose controller can be scripted.

The controller is ``easynav_controller/FaultyController`` (constant ``linear_vel``/``angular_vel``,
faults on demand), the localizer ``easynav_localizer/FaultyLocalizer`` (a fixed pose, stamped now),
the rest the Dummy plugins. Frequencies are high and timeouts short so each test takes little
time; the limits are fast ramps (0.1 s from full speed to zero, 0.15 s back).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from easynav.core.robot import RobotLimits
from easynav.system.testing.system_fixtures import system_params

#: robot_limits of every test (checked against what the driver receives).
LIMITS = RobotLimits(
    max_linear_vel=0.5,
    min_linear_vel=-0.2,
    max_angular_vel=1.0,
    max_linear_acc=2.0,
    max_linear_decel=3.0,
    max_angular_acc=4.0,
    max_angular_decel=6.0,
)
#: The controller's normal command.
LINEAR_VEL = 0.3
ANGULAR_VEL = 0.4
CMD_TIMEOUT = 0.2
RT_FREQ = 200.0
CONTROLLER_RT_FREQ = 50.0
#: Braking from (LINEAR_VEL, ANGULAR_VEL) to zero at the deceleration limits takes this long.
BRAKING_TIME = max(LINEAR_VEL / LIMITS.max_linear_decel, ANGULAR_VEL / LIMITS.max_angular_decel)

CONTROLLER = "easynav_controller/FaultyController"
LOCALIZER = "easynav_localizer/FaultyLocalizer"

BASE: dict[str, Any] = {
    "system_node": {"rt_freq": RT_FREQ, "freq": 50.0},
    "controller_node": {
        "controller_types": ["ctrl"],
        "ctrl": {
            "plugin": CONTROLLER,
            "rt_freq": CONTROLLER_RT_FREQ,
            "linear_vel": LINEAR_VEL,
            "angular_vel": ANGULAR_VEL,
        },
        "robot_limits": dataclasses.asdict(LIMITS),
        "cmd_timeout": CMD_TIMEOUT,
        # Stamped commands: the stamp is the node clock of the RT cycle that computed each one,
        # so every change between two commands can be checked against the limits exactly.
        "use_cmd_vel_stamped": True,
    },
    "localizer_node": {
        "localizer_types": ["loc"],
        "loc": {"plugin": LOCALIZER, "rt_freq": 50.0, "freq": 5.0},
    },
    "maps_manager_node": {
        "map_types": ["maps"],
        "maps": {"plugin": "easynav_maps_manager/DummyMapsManager", "freq": 10.0},
    },
    "planner_node": {
        "planner_types": ["plan"],
        "plan": {"plugin": "easynav_planner/DummyPlanner", "freq": 1.0},
    },
    "sensors_node": {"forget_time": 0.5},
    "recovery_node": {"recovery_manager": {"plugin": "easynav_recovery/DummyRecoveryManager"}},
}

#: What safety mode requires (plc_limits, a heartbeat period, a safety-status timeout, cmd_timeout
#: and a keepalive > 0, real time), with a tolerant RT monitor (a loaded test machine must not stop
#: EasyNav in tests that are not about late cycles).
SAFETY_MODE: dict[str, Any] = {
    "system_node.safety.mode": True,
    "system_node.safety.plc_limits.max_linear_vel": 1.0,
    "system_node.safety.plc_limits.max_angular_vel": 2.0,
    "system_node.safety.heartbeat.period": 0.05,
    "system_node.safety.status.timeout": 0.5,
    "system_node.safety.rt_monitor.max_period_factor": 20.0,
    "system_node.use_real_time": True,
    "controller_node.cmd_vel_keepalive_period": 0.05,
}


def system(**overrides: Any) -> dict[str, Any]:
    """The params document of :data:`BASE` with ``overrides`` (dotted paths, ``None`` removes):
    ``system(**{"controller_node.ctrl.fault": "nan"})``.
    """
    return system_params(BASE, **overrides)


def safety_mode_system(**overrides: Any) -> dict[str, Any]:
    """:func:`system` with every setting safety mode requires, then ``overrides``."""
    return system(**{**SAFETY_MODE, **overrides})


def fault(fault_name: str, fault_after: int = 0, node: str = "controller_node", **params: Any):
    """Overrides that make the plugin of ``node`` inject ``fault_name`` after ``fault_after``
    updates (the alias is ``ctrl`` for the controller, ``loc`` for the localizer).
    """
    alias = {"controller_node": "ctrl", "localizer_node": "loc"}[node]
    values = {"fault": fault_name, "fault_after": fault_after, **params}
    return {f"{node}.{alias}.{name}": value for name, value in values.items()}


