"""The seed's simple.params.yaml section for this package loads its plugin unchanged."""

from __future__ import annotations

import pytest
import yaml

from easynav.core.plugins import PluginContext
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import MAPS_MANAGER

pytestmark = pytest.mark.ros

# Verbatim from seed-design.txt (the Kobuki playground's simple.params.yaml, simplified).
SEED = """
maps_manager_node:
  ros__parameters:
    use_sim_time: true
    map_types: [simple]
    simple:
      freq: 10.0
      plugin: easynav_simple_maps_manager/SimpleMapsManager
      package: easynav_maps
      map_path_file: worlds/home.map
"""


def test_seed_section_configures_the_plugin_through_ros_parameters(tmp_path):
    rclpy = pytest.importorskip("rclpy")
    from easynav.core.system.node_parameters import NodeParameters

    params_file = tmp_path / "simple.params.yaml"
    params_file.write_text(SEED)
    section = yaml.safe_load(SEED)["maps_manager_node"]["ros__parameters"]
    assert section["map_types"] == ["simple"]
    context = rclpy.Context()
    rclpy.init(args=["--ros-args", "--params-file", str(params_file)], context=context)
    try:
        node = rclpy.create_node("maps_manager_node", context=context)
        cls = load_plugin_class(
            MAPS_MANAGER, section["simple"]["plugin"], "maps_manager_node.simple.plugin"
        )
        plugin = cls()
        plugin.initialize(
            PluginContext(
                parameters=NodeParameters(node), node=None, namespace="seed_maps_manager_node"
            ),
            "simple",
        )
        # The seed names easynav_playground_kobuki's maps/home.map; the same parameters find
        # the house shipped here (easynav-playground ships its own worlds the same way).
        assert plugin.freq == 10.0
        assert plugin.static_map.width == 280
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
