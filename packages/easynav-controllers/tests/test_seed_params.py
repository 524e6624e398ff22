"""The original EasyNav's example simple.params.yaml (the Kobuki playground's): this package's
section loads its plugin unchanged."""

from __future__ import annotations

import pytest

from easynav.core.plugins.plugin_kinds import CONTROLLER
from easynav.system.testing.params_section_plugin import plugin_from_params_section

pytestmark = pytest.mark.ros

# Verbatim from the original EasyNav's documentation ("Core Design and Architecture": the
# Kobuki playground's params/simple.params.yaml, simplified).
SEED = """
controller_node:
  ros__parameters:
    use_sim_time: true
    robot_limits:
      max_linear_vel: 0.6
      max_angular_vel: 1.0
    controller_types: [simple]
    simple:
      rt_freq: 30.0
      plugin: easynav_simple_controller/SimpleController
      look_ahead_dist: 0.2
      k_rot: 0.5
"""


def test_seed_section_configures_the_plugin_through_ros_parameters(tmp_path):
    pytest.importorskip("rclpy")
    seed = plugin_from_params_section(SEED, "controller_node", CONTROLLER, tmp_path)
    with seed as (plugin, section):
        assert section["controller_types"] == ["simple"]
        assert plugin.rt_freq == 30.0
        assert plugin.follower.look_ahead_dist == 0.2
        assert plugin.follower.k_rot == 0.5
        assert plugin.follower.tolerance_dist == 0.05  # the original's default
