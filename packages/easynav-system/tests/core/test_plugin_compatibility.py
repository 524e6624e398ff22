"""Map representations provided and needed: incompatible plugins are refused before starting."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from easynav.core.plugins import MapsManagerBase, PlannerMethodBase
from easynav.core.plugins.compatibility import compatibility_errors, compatible
from easynav.system.testing.system_fixtures import system_params

EASYNAV = str(Path(sys.executable).with_name("easynav"))


class GridMaps(MapsManagerBase):
    PROVIDES_MAPS = ("simple_map",)


class CostMaps(MapsManagerBase):
    PROVIDES_MAPS = ("costmap",)


class CostPlanner(PlannerMethodBase):
    NEEDS_MAPS = ("costmap",)


class AnyPlanner(PlannerMethodBase):
    pass


def test_a_need_is_met_by_any_one_provided_representation():
    assert compatible(("costmap", "navmap"), ("navmap",))
    assert compatible((), ())
    assert not compatible(("costmap",), ("simple_map",))


def test_the_error_names_both_plugins_and_what_each_provides_and_needs():
    errors = compatibility_errors({
        "maps_manager_node": [("simple", "pkg/GridMaps", GridMaps)],
        "planner_node": [("costmap", "pkg/CostPlanner", CostPlanner),
                         ("free", "pkg/AnyPlanner", AnyPlanner)],
    })
    assert errors == [
        "planner_node.costmap [pkg/CostPlanner] needs a map of type costmap, but "
        "maps_manager_node.simple [pkg/GridMaps] provides simple_map"
    ]


def test_two_maps_managers_provide_together():
    assert compatibility_errors({
        "maps_manager_node": [("a", "pkg/GridMaps", GridMaps), ("b", "pkg/CostMaps", CostMaps)],
        "planner_node": [("costmap", "pkg/CostPlanner", CostPlanner)],
    }) == []


class NavMaps(MapsManagerBase):
    PROVIDES_MAPS = ("navmap",)


class VoxelMaps(MapsManagerBase):
    PROVIDES_MAPS = ("costmap", "bonxai")


class SurfaceAndVoxelLocalizer(PlannerMethodBase):
    NEEDS_MAPS = ("navmap",)
    REQUIRES_MAPS = ("bonxai",)


def test_a_plugin_that_requires_two_maps_needs_both_managers():
    # The NavMap AMCL: predicts on the navmap, corrects on the bonxai voxels.
    assert not compatible(("navmap",), ("navmap",), ("bonxai",))
    assert compatible(("navmap",), ("navmap", "costmap", "bonxai"), ("bonxai",))
    loc = ("amcl", "pkg/SurfaceAndVoxelLocalizer", SurfaceAndVoxelLocalizer)
    assert compatibility_errors({
        "maps_manager_node": [("navmap", "pkg/NavMaps", NavMaps)],
        "localizer_node": [loc],
    }) == [
        "localizer_node.amcl [pkg/SurfaceAndVoxelLocalizer] needs maps of types bonxai, but "
        "maps_manager_node.navmap [pkg/NavMaps] provides navmap"
    ]
    assert compatibility_errors({
        "maps_manager_node": [("navmap", "pkg/NavMaps", NavMaps),
                              ("walls", "pkg/VoxelMaps", VoxelMaps)],
        "localizer_node": [loc],
    }) == []


@pytest.mark.ros
def test_easynav_check_refuses_a_planner_without_its_map(params_file):
    document = system_params(**{
        "planner_node.planner_types": ["simple"],
        "planner_node.simple": {"plugin": "easynav_simple_planner/SimplePlanner", "freq": 1.0},
    })
    result = subprocess.run(
        [EASYNAV, "check", params_file(document)], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 2, result.stdout
    assert (
        "planner_node.simple [easynav_simple_planner/SimplePlanner] needs a map of type "
        "simple_map, but no loaded maps manager provides a map"
    ) in result.stderr
