"""Before its first plan, a planner's ``path`` is empty: a controller waits for it."""

from __future__ import annotations

import pytest

from easynav.core.types import Path
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def test_a_planner_that_has_not_planned_yet_leaves_an_empty_path(params_file, runtime_factory):
    # The planner's first update hangs (as the non-RT thread did behind the OctoMap maps
    # manager building its voxel map): no path of its own yet, and an empty one in NavState.
    # A controller that drives to the first goal when no planner writes a path (VFF) sees
    # that one will come.
    planner = {"plugin": "easynav_planner/FaultyPlanner", "freq": 1.0, "fault": "hang",
               "fault_after": 0, "hang_time": 3.0}
    document = system_params(**{"planner_node.planner_types": ["plan"],
                                "planner_node.dummy": None, "planner_node.plan": planner})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    path = rt.nav_state.get("path", Path)
    assert len(path) == 0
    assert path.header.frame_id == "map"


@pytest.mark.parametrize("planners", [[], ["dummy"]])
def test_without_a_planner_that_writes_a_path_there_is_no_path(
        params_file, runtime_factory, planners):
    # The Dummy planner writes no path: a controller drives to the goal as with no planner.
    document = system_params(**{"planner_node.planner_types": planners})
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    assert not rt.nav_state.has("path")
