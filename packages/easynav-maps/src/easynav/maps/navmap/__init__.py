"""The NavMap stack's maps side: the NavMap type (a triangle surface with per-NavCel layers, the
original's ``navmap::NavMap``), its spatial index, builders and the ``.navmap`` file format."""

from easynav.maps.navmap.navmap import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    NavMap,
    Surface,
)
from easynav.maps.navmap.triangle_grid import TriangleGrid, locate_reference

__all__ = [
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "NO_INFORMATION",
    "NavMap",
    "Surface",
    "TriangleGrid",
    "locate_reference",
]
