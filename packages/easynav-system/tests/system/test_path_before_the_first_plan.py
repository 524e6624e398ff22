"""Before its first plan, a configured planner's ``path`` is empty: controllers wait for it."""

from __future__ import annotations

import pytest

from easynav.core.types import Path
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def test_an_active_planner_that_has_not_planned_yet_leaves_an_empty_path(
        params_file, runtime_factory):
    # The Dummy planner plans nothing: what it leaves is what every planner leaves before its
    # first plan (the non-RT thread busy elsewhere). A controller that drives to the first goal
    # when no planner writes a path (VFF) sees that one will come.
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    path = rt.nav_state.get("path", Path)
    assert len(path) == 0
    assert path.header.frame_id == "map"


def test_without_a_planner_there_is_no_path(params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params(**{"planner_node.planner_types": []})))
    assert rt.start(), rt.error
    assert not rt.nav_state.has("path")
