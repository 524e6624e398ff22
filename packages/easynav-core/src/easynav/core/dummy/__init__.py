"""Dummy plugins: one per component, for systems that do not need that component."""

from easynav.core.dummy.dummy_controller import DummyController
from easynav.core.dummy.dummy_localizer import DummyLocalizer
from easynav.core.dummy.dummy_maps_manager import DummyMapsManager
from easynav.core.dummy.dummy_planner import DummyPlanner
from easynav.core.dummy.dummy_recovery_manager import DummyRecoveryManager

__all__ = [
    "DummyController",
    "DummyLocalizer",
    "DummyMapsManager",
    "DummyPlanner",
    "DummyRecoveryManager",
]
