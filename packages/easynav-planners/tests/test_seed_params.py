"""The seed's simple.params.yaml section for this package loads its plugin unchanged."""

from __future__ import annotations

import pytest
import yaml

from easynav.core.plugins import PluginContext
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import PLANNER

pytestmark = pytest.mark.ros

# Verbatim from seed-design.txt (the Kobuki playground's simple.params.yaml, simplified).
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
    rclpy = pytest.importorskip("rclpy")
    from easynav.core.system.node_parameters import NodeParameters

    params_file = tmp_path / "simple.params.yaml"
    params_file.write_text(SEED)
    section = yaml.safe_load(SEED)["planner_node"]["ros__parameters"]
    assert section["planner_types"] == ["simple"]
    context = rclpy.Context()
    rclpy.init(args=["--ros-args", "--params-file", str(params_file)], context=context)
    try:
        node = rclpy.create_node("planner_node", context=context)
        cls = load_plugin_class(PLANNER, section["simple"]["plugin"], "planner_node.simple.plugin")
        plugin = cls()
        plugin.initialize(
            PluginContext(
                parameters=NodeParameters(node), node=None, namespace="seed_planner_node"
            ),
            "simple",
        )
        assert plugin.freq == 0.5
        assert plugin.planner.robot_radius == 0.3  # robot_geometry's default radius
        assert plugin.planner.clearance_distance == 0.2
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
