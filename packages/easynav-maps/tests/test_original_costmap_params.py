"""A costmap section written for the C++ original loads unchanged through ROS parameters."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginContext
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import MAPS_MANAGER
from easynav.maps.costmap import MAP

pytestmark = pytest.mark.ros

# The original's layout (easynav_plugins README / playground params): filters by alias, the
# filter's own parameters under <alias>.<filter>.*; map_path_file points at a map YAML here
# (the original resolved it in a ROS package's share directory).
ORIGINAL = """
maps_manager_node:
  ros__parameters:
    use_sim_time: false
    map_types: [costmap]
    costmap:
      freq: 10.0
      plugin: easynav_costmap_maps_manager/CostmapMapsManager
      package: ""
      map_path_file: {map}
      filters: [obstacles, inflation]
      obstacles:
        plugin: easynav_costmap_maps_manager/CostmapMapsManager/ObstaclesFilter
      inflation:
        plugin: easynav_costmap_maps_manager/CostmapMapsManager/InflationFilter
        inflation_radius: 0.6
        inscribed_radius: 0.25
        cost_scaling_factor: 3.0
"""


def test_original_section_configures_manager_and_filters(tmp_path):
    rclpy = pytest.importorskip("rclpy")
    from easynav.system.node_parameters import NodeParameters

    pixels = np.full((40, 40), 254, np.uint8)
    pixels[20, :] = 0
    cv2.imwrite(str(tmp_path / "m.pgm"), pixels)
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    params_file = tmp_path / "costmap.params.yaml"
    params_file.write_text(ORIGINAL.format(map=tmp_path / "m.yaml"))
    context = rclpy.Context()
    rclpy.init(args=["--ros-args", "--params-file", str(params_file)], context=context)
    try:
        node = rclpy.create_node("maps_manager_node", context=context)
        cls = load_plugin_class(
            MAPS_MANAGER, "easynav_costmap_maps_manager/CostmapMapsManager", "costmap.plugin"
        )
        manager = cls()
        manager.initialize(
            PluginContext(parameters=NodeParameters(node), namespace="original_costmap"),
            "costmap",
        )
        aliases = [alias for alias, _ in manager.filters]
        assert aliases == ["obstacles", "inflation"]
        inflation = manager.filters[1][1]
        assert inflation.params.inflation_radius == 0.6
        # robot_geometry keeps its default here: the deprecated inscribed_radius applies.
        assert inflation.inscribed_radius() == 0.25
        nav_state = NavState()
        manager.update(nav_state)
        live = nav_state.get(MAP)
        # Image row 20 of 40 is map row 19.
        assert live.data[19, 0] == 254 and live.data[24, 0] == 253  # 0.25 m: inscribed
        assert 0 < live.data[25, 0] < 253
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
