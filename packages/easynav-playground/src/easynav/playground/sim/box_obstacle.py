"""BoxObstacle: furniture with a height range (a low shelf, a table top, a table leg)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from easynav.playground.sim.world import World


@dataclass(frozen=True, slots=True)
class BoxObstacle:
    """An axis-aligned box ``[x0, x1] × [y0, y1] × [z0, z1]`` (m, map frame): a 2D laser at
    height ``h`` sees it only when ``z0 <= h <= z1``; the robot hits it when it overlaps
    ``[0, robot height]``; a 3D lidar sees it from any side.

    In a world description (``furniture:``)::

        - {name: low shelf, box: [7.5, 3.0, 8.5, 3.4], z: [0.3, 0.4]}

    Thread contract: an immutable value.
    """

    name: str
    x0: float
    y0: float
    x1: float
    y1: float
    z0: float
    z1: float

    @classmethod
    def from_dict(cls, spec: object, where: str) -> BoxObstacle:
        """Parse ``{name, box: [x0, y0, x1, y1], z: [z0, z1]}``.

        Raises:
            ValueError: a missing or malformed key, non-finite numbers or an empty box (names
                ``where``).
        """
        if not isinstance(spec, dict) or "box" not in spec or "z" not in spec:
            raise ValueError(f"{where}: needs 'box: [x0, y0, x1, y1]' and 'z: [z0, z1]'")
        unknown = set(spec) - {"name", "box", "z"}
        if unknown:
            raise ValueError(f"{where}: unknown keys {sorted(unknown)}")
        try:
            x0, y0, x1, y1 = (float(v) for v in spec["box"])
            z0, z1 = (float(v) for v in spec["z"])
        except (TypeError, ValueError) as err:
            raise ValueError(f"{where}: box must be 4 numbers and z 2 numbers: {err}") from err
        values = (x0, y0, x1, y1, z0, z1)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"{where}: box and z must be finite, got {values}")
        if not (x0 < x1 and y0 < y1 and 0.0 <= z0 < z1):
            raise ValueError(f"{where}: need x0 < x1, y0 < y1 and 0 <= z0 < z1, got {values}")
        return cls(str(spec.get("name", where)), *values)

    def overlaps_heights(self, low: float, high: float) -> bool:
        """Whether the box reaches into ``[low, high]``."""
        return self.z0 <= high and self.z1 >= low


def rasterize_boxes(
    world: World, boxes: Sequence[BoxObstacle], low: float, high: float
) -> World:
    """``world`` with the cells of the boxes reaching into heights ``[low, high]`` occupied
    (a cell is occupied when its square overlaps the box's)."""
    chosen = [b for b in boxes if b.overlaps_heights(low, high)]
    if not chosen:
        return world
    grid = world.occupied.copy()
    res = world.resolution
    for b in chosen:
        c0 = max(0, int(math.floor((b.x0 - world.origin_x) / res)))
        c1 = min(world.width, int(math.ceil((b.x1 - world.origin_x) / res)))
        r0 = max(0, int(math.floor((b.y0 - world.origin_y) / res)))
        r1 = min(world.height, int(math.ceil((b.y1 - world.origin_y) / res)))
        if c0 < c1 and r0 < r1:
            grid[r0:r1, c0:c1] = True
    return World(np.asarray(grid), res, world.origin_x, world.origin_y, name=world.name)
