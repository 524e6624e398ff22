"""The ``uneven`` world generated in code: an open field with a rock, a plateau and a hill.

24 x 16 m at 0.1 m, fenced. Heights (m) on flat ground at 0:

- a rock (1.2 m, 45 deg sides; top x 6.5..7.5, y 5..11, foot x 5.3..8.7, y 3.8..12.2) on the
  straight line from the start to the first waypoint and from the fourth to the fifth;
- a plateau (1.0 m; top x 16..22, y 10..14) with a 35 deg bank on its west side (on the straight
  line from the first waypoint to the second, on the plateau) and 45 deg sides elsewhere, reached
  only by a 15 deg ramp 3 m wide from the south (x 18..21, y 6.27..10, 45 deg sides);
- a gentle hill (0.4 m, at most 10 deg) around (12.5, 3.2), which may be driven over.

With the robot climbing up to 30 deg and a planner limit of 25 deg, only the ramp and the hill
are driven. Files (``python -m easynav.playground.uneven_world`` rewrites them; a test checks they
match): ``worlds/maps/uneven.yaml`` + ``.pgm`` (map-server occupancy: the fence) and
``worlds/maps/uneven_terrain.yaml`` + ``uneven_terrain_elevation.pgm`` (the heights in the GridMap
stack's original format, loaded by GridmapMapsManager and by the playground's terrain).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from easynav.playground.sim.world import World

RESOLUTION = 0.1
SIZE_X, SIZE_Y = 24.0, 16.0
FENCE = 0.1
ROCK_HEIGHT = 1.2
PLATEAU_HEIGHT = 1.0
RAMP_DEG = 15.0
BANK_DEG = 35.0
CLIFF_DEG = 45.0
HILL_HEIGHT, HILL_RADIUS = 0.4, 3.6


def _cell_centres() -> tuple[np.ndarray, np.ndarray]:
    xs = (np.arange(round(SIZE_X / RESOLUTION)) + 0.5) * RESOLUTION
    ys = (np.arange(round(SIZE_Y / RESOLUTION)) + 0.5) * RESOLUTION
    return np.meshgrid(xs, ys)


def uneven_elevation() -> np.ndarray:
    """Heights ``[iy, ix]`` (m) at the cell centres (exact; the shipped file holds 8 bits)."""
    x, y = _cell_centres()
    cliff = math.tan(math.radians(CLIFF_DEG))
    # Rock: a 45 deg fall from its top rectangle.
    d = np.hypot(np.maximum(np.maximum(6.5 - x, x - 7.5), 0.0),
                 np.maximum(np.maximum(5.0 - y, y - 11.0), 0.0))
    rock = ROCK_HEIGHT - cliff * d
    # Plateau: 35 deg bank to the west, 45 deg on the other sides.
    bank = math.tan(math.radians(BANK_DEG))
    fall = np.sqrt((bank * np.maximum(16.0 - x, 0.0)) ** 2
                   + (cliff * np.maximum(x - 22.0, 0.0)) ** 2
                   + (cliff * np.maximum(10.0 - y, 0.0)) ** 2
                   + (cliff * np.maximum(y - 14.0, 0.0)) ** 2)
    plateau = PLATEAU_HEIGHT - fall
    # Ramp: rises northward at 15 deg to the plateau's south edge; 45 deg sides.
    rise = np.clip(math.tan(math.radians(RAMP_DEG)) * (y - 10.0) + PLATEAU_HEIGHT, 0.0,
                   PLATEAU_HEIGHT)
    side = np.hypot(np.maximum(np.maximum(18.0 - x, x - 21.0), 0.0), np.maximum(y - 10.0, 0.0))
    ramp = rise - cliff * side
    # Gentle hill: a cosine bump (steepest slope atan(pi h / 2R) = 9.9 deg).
    r = np.hypot(x - 12.5, y - 3.2)
    hill = np.where(r < HILL_RADIUS,
                    0.5 * HILL_HEIGHT * (1.0 + np.cos(np.pi * np.minimum(r / HILL_RADIUS, 1.0))),
                    0.0)
    return np.maximum.reduce([rock, plateau, ramp, hill, np.zeros_like(x)])


def uneven_occupancy() -> World:
    """The occupancy world: open ground inside a fence (the heights are not walls)."""
    shape = (round(SIZE_Y / RESOLUTION), round(SIZE_X / RESOLUTION))
    grid = np.zeros(shape, dtype=bool)
    t = round(FENCE / RESOLUTION)
    grid[:t, :] = grid[-t:, :] = grid[:, :t] = grid[:, -t:] = True
    return World(grid, RESOLUTION, 0.0, 0.0, name="uneven")


def write_uneven_world(maps_dir: str | Path) -> list[Path]:
    """Write the occupancy map and the elevation map into ``maps_dir``; returns the YAMLs."""
    from easynav.maps.gridmap import GridMap, save_gridmap_yaml

    maps_dir = Path(maps_dir)
    occupancy = uneven_occupancy().save_map_server_yaml(maps_dir / "uneven.yaml")
    terrain = save_gridmap_yaml(
        GridMap.from_elevation(uneven_elevation(), RESOLUTION), maps_dir / "uneven_terrain.yaml"
    )
    return [occupancy, terrain]


if __name__ == "__main__":
    target = sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent / "worlds" / "maps"
    for p in write_uneven_world(target):
        print(p)
