"""NavState keys of the voxel maps managers, declared once."""

from __future__ import annotations

from easynav.core.nav_state_keys import NavStateKey

MAP_BONXAI = NavStateKey(
    "map.bonxai",
    "BonxaiMap",
    "the Bonxai-style probabilistic voxel map (BonxaiMapsManager); written once when absent, "
    "as the original: the object is updated in place, so readers (the NavMap localizer) see "
    "its changes without re-reading the key.",
)

MAP_OCTOMAP = NavStateKey(
    "map.octomap",
    "OctomapMap",
    "the OctoMap voxel map (OctomapMapsManager), written once when absent and updated in place.",
)
