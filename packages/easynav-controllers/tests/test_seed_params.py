"""The seed's simple.params.yaml section for this package loads its plugin unchanged."""

from __future__ import annotations

import pytest
import yaml

from easynav.core.plugins import PluginContext
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import CONTROLLER

pytestmark = pytest.mark.ros

# Verbatim from seed-design.txt (the Kobuki playground's simple.params.yaml, simplified).
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
    rclpy = pytest.importorskip("rclpy")
    from easynav.core.system.node_parameters import NodeParameters

    params_file = tmp_path / "simple.params.yaml"
    params_file.write_text(SEED)
    section = yaml.safe_load(SEED)["controller_node"]["ros__parameters"]
    assert section["controller_types"] == ["simple"]
    context = rclpy.Context()
    rclpy.init(args=["--ros-args", "--params-file", str(params_file)], context=context)
    try:
        node = rclpy.create_node("controller_node", context=context)
        cls = load_plugin_class(
            CONTROLLER, section["simple"]["plugin"], "controller_node.simple.plugin"
        )
        plugin = cls()
        plugin.initialize(
            PluginContext(
                parameters=NodeParameters(node), node=None, namespace="seed_controller_node"
            ),
            "simple",
        )
        assert plugin.rt_freq == 30.0
        assert plugin.follower.look_ahead_dist == 0.2
        assert plugin.follower.k_rot == 0.5
        assert plugin.follower.tolerance_dist == 0.05  # the original's default
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
