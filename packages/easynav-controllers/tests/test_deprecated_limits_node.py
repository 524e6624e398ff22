"""controller_node applies MPC's and VFF's own (deprecated) limit names to robot_limits."""

from __future__ import annotations

import pytest

from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def controller(alias: str, plugin: str, **params) -> dict:
    return {
        "controller_node.controller_types": [alias],
        "controller_node.dummy": None,
        f"controller_node.{alias}": {"rt_freq": 20.0, "plugin": plugin, **params},
    }


@pytest.mark.parametrize(
    ("alias", "plugin", "params"),
    [
        ("mpc", "easynav_mpc_controller/MPCController",
         {"max_linear_velocity": 0.3, "max_angular_velocity": 0.7}),
        ("vff", "easynav_vff_controller/VffController",
         {"max_speed": 0.3, "max_angular_speed": 0.7}),
    ],
)
def test_original_limit_names_stand_for_robot_limits(
    params_file, runtime_factory, alias, plugin, params
):
    rt = runtime_factory(params_file(system_params(**controller(alias, plugin, **params))))
    assert rt.start(), rt.error
    limits = rt.system_node.subnodes["controller_node"].robot_limits
    assert limits.max_linear_vel == 0.3 and limits.max_angular_vel == 0.7


def test_explicit_robot_limits_win(params_file, runtime_factory):
    document = system_params(
        **controller("mpc", "easynav_mpc_controller/MPCController", max_linear_velocity=0.3),
        **{"controller_node.robot_limits": {"max_linear_vel": 0.4}},
    )
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    assert rt.system_node.subnodes["controller_node"].robot_limits.max_linear_vel == 0.4
