"""Generate ``easynav/maps/worlds/uneven_terrain.yaml`` (+ ``uneven_terrain_elevation.pgm``).

An uneven world for the GridMap stack, in the original's gridmap format: 12 m x 8 m at 0.1 m,
centred on (6, 4). Flat ground at 0 m; a plateau 0.8 m high (x 7.5..11.5, y 0.5..7.5) reached
only by a 15 deg ramp from the west at y 1..3 (its other sides are 60 deg cliffs); a 45 deg mound
(peak near 1 m) at (4, 5.5). With a 30 deg limit a planner must take the ramp to reach the plateau
and go round the mound. Run ``python tools/make_gridmap_world.py`` to regenerate.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from easynav.maps.gridmap import GridMap, save_gridmap_yaml

RESOLUTION = 0.1
WIDTH, HEIGHT = 12.0, 8.0
PLATEAU_Z = 0.8


def uneven_terrain() -> GridMap:
    """The world as a GridMap (exact heights; the file holds them to 8 bits)."""
    xs = (np.arange(round(WIDTH / RESOLUTION)) + 0.5) * RESOLUTION
    ys = (np.arange(round(HEIGHT / RESOLUTION)) + 0.5) * RESOLUTION
    x, y = np.meshgrid(xs, ys)
    # Plateau: distance outside the rectangle, falling at 60 deg.
    dx = np.maximum(np.maximum(7.5 - x, x - 11.5), 0.0)
    dy = np.maximum(np.maximum(0.5 - y, y - 7.5), 0.0)
    plateau = np.clip(PLATEAU_Z - math.tan(math.radians(60)) * np.hypot(dx, dy), 0.0, None)
    # Ramp: rises at 15 deg westward to the plateau's edge, 1 m < y < 3 m.
    ramp_len = PLATEAU_Z / math.tan(math.radians(15))
    ramp = np.where((y > 1.0) & (y < 3.0),
                    np.clip(PLATEAU_Z - math.tan(math.radians(15)) * (7.5 - x), 0.0, PLATEAU_Z),
                    0.0)
    ramp[x < 7.5 - ramp_len] = 0.0
    mound = np.clip(1.0 - math.tan(math.radians(45)) * np.hypot(x - 4.0, y - 5.5), 0.0, None)
    z = np.maximum(np.maximum(plateau, ramp), mound)
    return GridMap.from_elevation(z, RESOLUTION)


def main() -> None:
    out = Path(__file__).resolve().parents[1] / "src/easynav/maps/worlds/uneven_terrain.yaml"
    save_gridmap_yaml(uneven_terrain(), out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
