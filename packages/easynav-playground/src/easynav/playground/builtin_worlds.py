"""Built-in worlds generated in code: a house, an office and a hall for two robots (crossing),
drawn with rectangles in metres.

The shipped ``worlds/<name>.map`` files are these grids saved (regenerate them with
``python -m easynav.playground.builtin_worlds``; a test checks that they match). Walls and
doors sit on multiples of 0.2 m and doors are 1.6 m wide in the house (1.2 m, the least
that SimplePlanner's 0.2 m grid with a 0.3 m robot plus 0.2 m clearance passes, in the office),
so that the simple stack has some room to spare.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from easynav.playground.sim.world import World

RESOLUTION = 0.05
WALL = 0.1


class _Canvas:
    """A grid being drawn in metres (helper of the builders below)."""

    def __init__(self, size_x: float, size_y: float) -> None:
        self.grid = np.zeros((round(size_y / RESOLUTION), round(size_x / RESOLUTION)), dtype=bool)

    def fill(self, x0: float, y0: float, x1: float, y1: float, value: bool = True) -> None:
        """Set every cell whose centre lies in ``[x0, x1] x [y0, y1]``."""
        c0, c1 = round(x0 / RESOLUTION), round(x1 / RESOLUTION)
        r0, r1 = round(y0 / RESOLUTION), round(y1 / RESOLUTION)
        self.grid[r0:r1, c0:c1] = value

    def outer_walls(self) -> None:
        h, w = self.grid.shape
        t = round(WALL / RESOLUTION)
        self.grid[:t, :] = self.grid[h - t :, :] = True
        self.grid[:, :t] = self.grid[:, w - t :] = True

    def wall_x(self, x: float, y0: float, y1: float, doors: tuple = ()) -> None:
        """A vertical wall at ``x`` (thickness WALL) from ``y0`` to ``y1`` with door gaps."""
        self.fill(x, y0, x + WALL, y1)
        for d0, d1 in doors:
            self.fill(x, d0, x + WALL, d1, False)

    def wall_y(self, y: float, x0: float, x1: float, doors: tuple = ()) -> None:
        """A horizontal wall at ``y`` (thickness WALL) from ``x0`` to ``x1`` with door gaps."""
        self.fill(x0, y, x1, y + WALL)
        for d0, d1 in doors:
            self.fill(d0, y, d1, y + WALL, False)


def build_home() -> World:
    """A 10 x 8 m house: living room, kitchen, two bedrooms, furniture; 0.05 m cells."""
    c = _Canvas(10.0, 8.0)
    c.outer_walls()
    c.wall_x(4.0, 0.0, 8.0, doors=((1.2, 2.8), (5.6, 7.2)))  # bedrooms | living, kitchen
    c.wall_y(4.0, 0.0, 4.0, doors=((2.0, 3.6),))  # bedroom 1 | bedroom 2
    c.wall_y(5.0, 4.0, 10.0, doors=((6.2, 7.8),))  # living room | kitchen
    c.fill(6.6, 1.6, 7.6, 2.4)  # living room: table
    c.fill(8.2, 0.1, 9.9, 0.7)  # living room: sofa
    c.fill(4.1, 7.4, 7.0, 7.9)  # kitchen: counter
    c.fill(8.2, 6.2, 9.0, 6.8)  # kitchen: island
    c.fill(0.1, 0.1, 2.0, 1.2)  # bedroom 1: bed
    c.fill(0.1, 3.0, 0.7, 3.9)  # bedroom 1: wardrobe
    c.fill(0.1, 5.8, 1.6, 7.9)  # bedroom 2: bed
    c.fill(2.6, 7.4, 3.9, 7.9)  # bedroom 2: desk
    return World(c.grid, RESOLUTION, 0.0, 0.0, name="home")


def build_office() -> World:
    """A 16 x 10 m office floor: a corridor with three offices on each side; 0.05 m cells."""
    c = _Canvas(16.0, 10.0)
    c.outer_walls()
    c.wall_y(4.0, 0.0, 16.0, doors=((1.8, 3.0), (7.4, 8.6), (12.8, 14.0)))
    c.wall_y(6.0, 0.0, 16.0, doors=((2.4, 3.6), (6.8, 8.0), (12.2, 13.4)))
    for x in (5.2, 10.6):
        c.wall_x(x, 0.0, 4.0)
        c.wall_x(x, 6.0, 10.0)
    for x0 in (0.8, 6.2, 11.6):  # a desk in every office, against the outer walls
        c.fill(x0, 0.1, x0 + 1.6, 0.8)
        c.fill(x0 + 1.8, 9.2, x0 + 3.4, 9.9)
    c.fill(4.0, 2.0, 4.6, 2.6)  # cabinets
    c.fill(15.2, 7.6, 15.9, 8.4)
    return World(c.grid, RESOLUTION, 0.0, 0.0, name="office")


def build_crossing() -> World:
    """A 10 x 7 m hall for two robots whose paths cross (worlds/crossing.yaml): open in the
    middle, with pillars and cabinets along the walls for the localizer; 0.05 m cells."""
    c = _Canvas(10.0, 7.0)
    c.outer_walls()
    c.fill(0.1, 4.6, 0.7, 5.8)  # cabinet, west wall
    c.fill(6.0, 6.3, 7.6, 6.9)  # shelf, north wall
    c.fill(9.3, 0.1, 9.9, 1.0)  # cabinet, south-east corner
    c.fill(5.4, 4.4, 5.8, 4.8)  # pillar
    c.fill(7.6, 3.6, 8.0, 4.0)  # pillar
    c.fill(1.2, 0.1, 2.2, 0.5)  # low bench, south wall
    return World(c.grid, RESOLUTION, 0.0, 0.0, name="crossing")


BUILTIN_WORLDS: dict[str, Callable[[], World]] = {
    "home": build_home,
    "office": build_office,
    "crossing": build_crossing,
}


def write_builtin_maps(directory: str | Path) -> list[Path]:
    """Save every built-in world as ``<directory>/<name>.map``; returns the paths."""
    paths = []
    for name, build in BUILTIN_WORLDS.items():
        path = Path(directory) / f"{name}.map"
        build().save_map_file(path)
        paths.append(path)
    return paths


if __name__ == "__main__":
    target = sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent / "worlds"
    for p in write_builtin_maps(target):
        print(p)
