"""EasyNav fault-injection plugins: FaultyController, FaultyLocalizer, FaultyPlanner and
FaultyMapsManager, registered under the original names (``easynav_controller/FaultyController``
...). Each works normally, then injects ``<alias>.fault`` after ``<alias>.fault_after`` updates.
"""

from easynav.faulty.fault_injector import NO_FAULT, FaultInjector, InjectedFaultError
from easynav.faulty.faulty_controller import FaultyController
from easynav.faulty.faulty_localizer import FaultyLocalizer
from easynav.faulty.faulty_maps_manager import FaultyMapsManager
from easynav.faulty.faulty_planner import FaultyPlanner, straight_path

__all__ = [
    "NO_FAULT",
    "FaultInjector",
    "FaultyController",
    "FaultyLocalizer",
    "FaultyMapsManager",
    "FaultyPlanner",
    "InjectedFaultError",
    "straight_path",
]
