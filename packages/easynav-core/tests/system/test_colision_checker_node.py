"""controller_node's colision_checker.* parameters and its check after the controller."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.core.sensors import PointPerception
from easynav.core.testing.system_fixtures import system_params
from easynav.core.types import Header, Twist, TwistStamped

pytestmark = pytest.mark.ros


def test_inactive_by_default(params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    assert rt.system_node.subnodes["controller_node"].colision_checker is None


def test_active_checker_zeroes_a_command_into_a_point(params_file, runtime_factory):
    document = system_params(**{
        "controller_node.colision_checker.active": True,
        "controller_node.colision_checker.robot_radius": 0.3,
    })
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    node = rt.system_node.subnodes["controller_node"]
    assert node.colision_checker is not None and node.colision_checker.robot_radius == 0.3
    node.active = False  # keep the dummy controller from writing cmd_vel meanwhile
    nav_state = node.nav_state
    frame = node.robot_frame()
    nav_state.set("scan", PointPerception(np.array([[0.5, 0.0, 0.2]]), frame, 0.0))
    command = TwistStamped(Header(1.0, "base_footprint"), Twist(vx=0.5, wz=0.0))
    nav_state.set("cmd_vel", command)
    node.check_collision()
    stopped = nav_state.get("cmd_vel", TwistStamped)
    assert stopped.twist.is_zero() and stopped.header.frame_id == "base_footprint"
    # A command that turns away from the point and one beside it pass unchanged.
    nav_state.set("scan", PointPerception(np.array([[0.5, 0.5, 0.2]]), frame, 0.0))
    nav_state.set("cmd_vel", command)
    node.check_collision()
    assert nav_state.get("cmd_vel", TwistStamped) is command


def test_bad_value_fails_configuration_naming_it(params_file, runtime_factory):
    document = system_params(**{"controller_node.colision_checker.brake_acc": -1.0})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "colision_checker.brake_acc = -1.0" in rt.error
