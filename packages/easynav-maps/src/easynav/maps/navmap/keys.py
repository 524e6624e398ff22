"""NavState keys of the NavMap stack (the name the original EasyNav's NavMapMapsManager writes,
``map.navmap``), declared once.

Planners and localizers working on a NavMap import this constant instead of writing the string.
"""

from __future__ import annotations

from easynav.core.nav_state_keys import NavStateKey

MAP_NAVMAP = NavStateKey(
    "map.navmap",
    "NavMap",
    "the NavMap (easynav.maps.navmap.NavMap): the loaded or received mesh with its layers "
    "(occupancy from a grid map; obstacles, inflated_obstacles from the filters), rebuilt from "
    "the previous cycle's map through the filters every cycle (NavMapMapsManager).",
)
