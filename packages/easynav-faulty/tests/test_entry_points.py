"""The four plugins are found by their original names, in the right kinds."""

from __future__ import annotations

import pytest

from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import CONTROLLER, LOCALIZER, MAPS_MANAGER, PLANNER
from easynav.faulty import FaultyController, FaultyLocalizer, FaultyMapsManager, FaultyPlanner


@pytest.mark.parametrize(
    ("kind", "name", "cls"),
    [
        (CONTROLLER, "easynav_controller/FaultyController", FaultyController),
        (LOCALIZER, "easynav_localizer/FaultyLocalizer", FaultyLocalizer),
        (PLANNER, "easynav_planner/FaultyPlanner", FaultyPlanner),
        (MAPS_MANAGER, "easynav_maps_manager/FaultyMapsManager", FaultyMapsManager),
    ],
)
def test_plugin_is_registered_under_its_original_name(kind, name, cls):
    assert load_plugin_class(kind, name, "test.plugin") is cls
