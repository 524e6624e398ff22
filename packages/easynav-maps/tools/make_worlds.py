"""Generate the `.map` worlds shipped in easynav/maps/worlds/ (run from anywhere).

    python packages/easynav-maps/tools/make_worlds.py

The worlds are drawn from rectangles in metres, so they can be regenerated and reviewed here
instead of as 50 000 digits. Doors are 1.4 m wide: SimplePlanner keeps 0.5 m of clearance
(robot_radius + clearance_distance) on a 0.2 m grid, which needs about 1.2 m of free width.
"""

from __future__ import annotations

from pathlib import Path

from easynav.maps import SimpleMap

WORLDS = Path(__file__).resolve().parents[1] / "src" / "easynav" / "maps" / "worlds"
RESOLUTION = 0.05
WALL = 0.1


def blank(min_x: float, min_y: float, max_x: float, max_y: float) -> SimpleMap:
    """A free map covering the rectangle, with a 0.1 m wall along its border."""
    width = round((max_x - min_x) / RESOLUTION)
    height = round((max_y - min_y) / RESOLUTION)
    world = SimpleMap(width, height, RESOLUTION, min_x, min_y)
    box(world, min_x, min_y, max_x, min_y + WALL)
    box(world, min_x, max_y - WALL, max_x, max_y)
    box(world, min_x, min_y, min_x + WALL, max_y)
    box(world, max_x - WALL, min_y, max_x, max_y)
    return world


def box(world: SimpleMap, x0: float, y0: float, x1: float, y1: float) -> None:
    """Mark the cells whose centres lie in the rectangle [x0, x1] × [y0, y1] occupied."""
    ix0, iy0 = (int(v) for v in world.world_to_cell(x0 + 1e-6, y0 + 1e-6))
    ix1, iy1 = (int(v) for v in world.world_to_cell(x1 - 1e-6, y1 - 1e-6))
    world.cells[max(iy0, 0) : iy1 + 1, max(ix0, 0) : ix1 + 1] = True


def wall_x(world: SimpleMap, x: float, y0: float, y1: float, doors=()) -> None:
    """A vertical wall at x from y0 to y1, open on each (door_y0, door_y1) interval."""
    cuts = [y0, *[v for d in sorted(doors) for v in d], y1]
    for a, b in zip(cuts[::2], cuts[1::2], strict=True):
        box(world, x - WALL / 2, a, x + WALL / 2, b)


def wall_y(world: SimpleMap, y: float, x0: float, x1: float, doors=()) -> None:
    """A horizontal wall at y from x0 to x1, open on each (door_x0, door_x1) interval."""
    cuts = [x0, *[v for d in sorted(doors) for v in d], x1]
    for a, b in zip(cuts[::2], cuts[1::2], strict=True):
        box(world, a, y - WALL / 2, b, y + WALL / 2)


def home() -> SimpleMap:
    """A 14 m x 10 m house: living room (robot starts at 0, 0), kitchen, two bedrooms."""
    world = blank(-2.0, -2.0, 12.0, 8.0)
    wall_x(world, 5.0, -2.0, 8.0, doors=[(0.0, 1.4), (5.0, 6.4)])  # living | kitchen, bed1 | bed2
    wall_y(world, 4.0, -2.0, 5.0, doors=[(1.6, 3.0)])  # living | bedroom 1
    wall_y(world, 3.5, 5.0, 12.0, doors=[(8.0, 9.4)])  # kitchen | bedroom 2
    box(world, 2.0, -0.6, 3.2, 0.2)  # living-room table
    box(world, -1.9, 1.5, -1.2, 3.5)  # sofa along the west wall
    box(world, 3.6, 3.3, 4.95, 3.95)  # bookshelf
    box(world, 7.8, -0.2, 9.4, 0.6)  # kitchen island
    box(world, 10.9, -1.9, 11.9, 1.5)  # kitchen counter
    box(world, -1.9, 6.0, -0.2, 7.9)  # bed (bedroom 1)
    box(world, 3.8, 6.8, 4.95, 7.9)  # wardrobe (bedroom 1)
    box(world, 10.0, 5.8, 11.9, 7.9)  # bed (bedroom 2)
    box(world, 5.05, 7.3, 6.5, 7.9)  # desk (bedroom 2)
    return world


def empty_room() -> SimpleMap:
    """A 6 m x 6 m room centred on the origin, walls only."""
    return blank(-3.0, -3.0, 3.0, 3.0)


def corridor() -> SimpleMap:
    """A 12 m x 2 m corridor from x = -1 with three pillars on alternate sides."""
    world = blank(-1.0, -1.0, 11.0, 1.0)
    for x, side in ((2.5, -1.0), (5.5, 1.0), (8.5, -1.0)):
        y0 = -0.9 if side < 0 else 0.5
        box(world, x - 0.2, y0, x + 0.2, y0 + 0.4)
    return world


def main() -> None:
    WORLDS.mkdir(parents=True, exist_ok=True)
    for name, world in (("home", home()), ("empty_room", empty_room()), ("corridor", corridor())):
        path = WORLDS / f"{name}.map"
        world.save(path)
        print(f"{path}: {world}")


if __name__ == "__main__":
    main()
