"""The original's parameters of MPC, SeReST and VFF load unchanged (names, types, values)."""

from __future__ import annotations

import pytest
from closed_loop import make_plugin

from easynav.controllers.mpc_controller import MPCController
from easynav.controllers.serest_controller import SerestController
from easynav.controllers.serest_tracker import SEREST_DEFAULTS
from easynav.controllers.vff_controller import VffController
from easynav.core.plugins.declarations import declared_names

ORIGINAL = {
    MPCController: {
        "horizon_steps": 5, "dt": 0.1, "safety_radius": 0.35, "max_linear_velocity": 1.5,
        "max_angular_velocity": 1.5, "verbose": False, "fallback_goal_pos_tol": 0.05,
        "fallback_goal_yaw_tol": 0.05,
    },
    SerestController: SEREST_DEFAULTS | {
        "max_linear_speed": 0.6, "max_angular_speed": 1.5, "max_linear_acc": 0.8,
        "max_angular_acc": 2.0,
    },
    VffController: {
        "distance_obstacle_detection": 3.0, "distance_to_goal": 1.0,
        "obstacle_detection_x_min": 0.5, "obstacle_detection_x_max": 10.0,
        "obstacle_detection_y_min": -10.0, "obstacle_detection_y_max": 10.0,
        "obstacle_detection_z_min": 0.10, "obstacle_detection_z_max": 1.00, "max_speed": 0.8,
        "max_angular_speed": 1.5,
    },
}


@pytest.mark.parametrize("cls", list(ORIGINAL), ids=lambda c: c.__name__)
def test_every_original_parameter_is_declared_and_loads(cls):
    params = ORIGINAL[cls]
    assert set(params) <= declared_names(cls.parameter_declarations())
    plugin = make_plugin(cls, "ctrl", params)
    for name, value in params.items():
        assert plugin.params[name] == value, name


@pytest.mark.parametrize("cls", list(ORIGINAL), ids=lambda c: c.__name__)
def test_original_defaults_are_the_defaults(cls):
    defaults = {p.name: p.default for p in cls.parameter_declarations()}
    for name, value in ORIGINAL[cls].items():
        if name.startswith("max_"):
            continue  # deprecated limits: unset, robot_limits rules
        assert defaults[name] == value, name
