"""The original EasyNav's example simple.params.yaml (the Kobuki playground's): this package's
section loads its plugin unchanged."""

from __future__ import annotations

import pytest

from easynav.core.plugins.plugin_kinds import PLANNER
from easynav.system.testing.params_section_plugin import plugin_from_params_section

pytestmark = pytest.mark.ros

# Verbatim from the original EasyNav's documentation ("Core Design and Architecture": the
# Kobuki playground's params/simple.params.yaml, simplified).
SEED = """
planner_node:
  ros__parameters:
    use_sim_time: true
    planner_types: [simple]
    simple:
      freq: 0.5
      plugin: easynav_simple_planner/SimplePlanner
"""


def test_seed_section_configures_the_plugin_through_ros_parameters(tmp_path):
    pytest.importorskip("rclpy")
    seed = plugin_from_params_section(SEED, "planner_node", PLANNER, tmp_path)
    with seed as (plugin, section):
        assert section["planner_types"] == ["simple"]
        assert plugin.freq == 0.5
        assert plugin.planner.robot_radius == 0.3  # robot_geometry's default radius
        assert plugin.planner.clearance_distance == 0.2
