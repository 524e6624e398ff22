"""The original EasyNav's example simple.params.yaml (the Kobuki playground's): this package's
section loads its plugin unchanged."""

from __future__ import annotations

import pytest

from easynav.core.plugins.plugin_kinds import MAPS_MANAGER
from easynav.system.testing.params_section_plugin import plugin_from_params_section

pytestmark = pytest.mark.ros

# Verbatim from the original EasyNav's documentation ("Core Design and Architecture": the
# Kobuki playground's params/simple.params.yaml, simplified).
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
    pytest.importorskip("rclpy")
    seed = plugin_from_params_section(SEED, "maps_manager_node", MAPS_MANAGER, tmp_path)
    with seed as (plugin, section):
        assert section["map_types"] == ["simple"]
        # The seed names easynav_playground_kobuki's maps/home.map; the same parameters find
        # the house shipped here (easynav-playground ships its own worlds the same way).
        assert plugin.freq == 10.0
        assert plugin.static_map.width == 280
