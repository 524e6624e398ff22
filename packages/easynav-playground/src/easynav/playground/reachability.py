"""Which places SimplePlanner can reach: its planning grid and an 8-connected flood fill.

Used to check waypoint lists before a run and by the tests of the shipped worlds. It mirrors
SimplePlanner's rules (the original EasyNav's: 8-connected A* on the map downsampled to 0.2 m, cells
free within robot_radius 0.3 + clearance_distance 0.2) without depending on the planner package: the
map is downsampled by an integer factor (a coarse cell is occupied when any fine cell in it is), and
a coarse cell is usable when no occupied coarse cell lies within ``robot_radius + clearance``
(centre to centre, in cells).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import cv2
import numpy as np

from easynav.playground.sim.world import World


def planning_grid(world: World, cell_size: float = 0.2) -> tuple[np.ndarray, float]:
    """The coarse occupancy grid ``(rows, cols)`` and its resolution (floor of the factor)."""
    factor = max(int(math.floor(cell_size / world.resolution + 1e-9)), 1)
    rows, cols = world.height // factor, world.width // factor
    fine = world.occupied[: rows * factor, : cols * factor]
    coarse = fine.reshape(rows, factor, cols, factor).any(axis=(1, 3))
    return coarse, world.resolution * factor


def usable_cells(
    world: World, cell_size: float = 0.2, robot_radius: float = 0.3, clearance: float = 0.2
) -> tuple[np.ndarray, float]:
    """Mask of coarse cells the planner may enter, and the coarse resolution."""
    coarse, res = planning_grid(world, cell_size)
    radius_cells = (robot_radius + clearance) / res
    r = int(math.ceil(radius_cells))
    dy, dx = np.mgrid[-r : r + 1, -r : r + 1]
    kernel = (np.hypot(dx, dy) <= radius_cells).astype(np.uint8)
    blocked = cv2.dilate(
        coarse.astype(np.uint8), kernel, borderType=cv2.BORDER_CONSTANT, borderValue=0
    )
    return blocked == 0, res


def reachable_from(
    world: World,
    start: tuple[float, float],
    targets: Iterable[tuple[float, float]],
    cell_size: float = 0.2,
    robot_radius: float = 0.3,
    clearance: float = 0.2,
) -> list[bool]:
    """For each target ``(x, y)``, whether an 8-connected path of usable cells joins it to start.

    As in SimplePlanner the start cell itself need not be usable (the robot may start close to
    a wall), but the path leaves it through a usable neighbour and ends in a usable cell.
    """
    usable, res = usable_cells(world, cell_size, robot_radius, clearance)
    _, labels = cv2.connectedComponents(usable.astype(np.uint8), connectivity=8)
    rows, cols = usable.shape

    def cell(x: float, y: float) -> tuple[int, int]:
        return (
            int(math.floor((y - world.origin_y) / res)),
            int(math.floor((x - world.origin_x) / res)),
        )

    sr, sc = cell(*start)
    start_labels = set()
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            r, c = sr + dr, sc + dc
            if 0 <= r < rows and 0 <= c < cols and usable[r, c]:
                start_labels.add(int(labels[r, c]))
    result = []
    for x, y in targets:
        r, c = cell(x, y)
        inside = 0 <= r < rows and 0 <= c < cols
        result.append(bool(inside and usable[r, c] and int(labels[r, c]) in start_labels))
    return result
