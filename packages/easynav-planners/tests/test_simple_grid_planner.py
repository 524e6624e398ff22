"""SimpleGridPlanner on SimpleMaps: clearance disc, reasons, start escape, shipped worlds."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from easynav.maps import SimpleMap, resolve_map_file
from easynav.planners import SimpleGridPlanner, astar_8connected


def room(width_m=6.0, height_m=4.0, res=0.05) -> SimpleMap:
    world = SimpleMap(round(width_m / res), round(height_m / res), res, 0.0, 0.0)
    world.cells[0, :] = world.cells[-1, :] = world.cells[:, 0] = world.cells[:, -1] = True
    return world


def clearance_along(world: SimpleMap, poses: np.ndarray) -> float:
    """Smallest distance from the path (sampled every cm) to an occupied cell's edge."""
    samples = []
    for a, b in zip(poses[:-1, :2], poses[1:, :2], strict=True):
        n = max(1, int(math.hypot(*(b - a)) / 0.01))
        samples.append(a + np.linspace(0, 1, n + 1)[:, None] * (b - a))
    pts = np.vstack(samples)
    iy, ix = np.nonzero(world.cells)
    cx, cy = world.cell_to_world(ix, iy)
    d = np.hypot(pts[:, None, 0] - cx[None], pts[:, None, 1] - cy[None]).min()
    return float(d - world.resolution / 2 * math.sqrt(2))


def test_path_keeps_the_robot_disc_clear_of_a_pillar():
    world = room()
    world.cells[30:50, 55:65] = True  # a 0.5 x 1.0 m pillar in the middle
    for smooth in (False, True):
        result = SimpleGridPlanner(0.3, 0.2, smooth=smooth).plan(world, (1.0, 2.0), (5.0, 2.0, 0.5))
        assert result.ok, result.reason
        assert result.poses[0, :2].tolist() == [1.0, 2.0]
        assert result.poses[-1].tolist() == [5.0, 2.0, 0.5]
        # Coarse 0.2 m cells: the 0.5 m clearance holds up to the discretisation of the map.
        assert clearance_along(world, result.poses[1:-1]) > 0.3 + 0.05
        assert 4.0 < result.length < 6.0


def test_smoothing_shortens_the_staircase():
    world = room(8.0, 8.0)
    raw = SimpleGridPlanner(smooth=False).plan(world, (1.0, 1.0), (7.0, 4.0, 0.0))
    smooth = SimpleGridPlanner(smooth=True).plan(world, (1.0, 1.0), (7.0, 4.0, 0.0))
    straight = math.hypot(6.0, 3.0)
    assert smooth.length == pytest.approx(straight, abs=0.05)
    assert raw.length > smooth.length + 0.2
    spacing = np.hypot(*np.diff(smooth.poses[:, :2], axis=0).T)
    assert spacing.max() <= 0.2 + 1e-9  # resampled for controllers that look ahead by distance


def test_reasons_name_the_goal():
    world = room()
    world.cells[:, 60:62] = True  # a wall splitting the room
    planner = SimpleGridPlanner()
    cases = {
        (5.0, 2.0, 0.0): r"goal \(5.00, 2.00\) is unreachable from \(1.00, 2.00\)",
        (3.02, 2.0, 0.0): r"goal \(3.02, 2.00\) is inside an obstacle",
        (3.25, 2.0, 0.0): "closer than robot_radius to an obstacle",
        (3.45, 2.0, 0.0): "closer than robot_radius \\+ clearance_distance",
        (9.0, 2.0, 0.0): "goal \\(9.00, 2.00\\) is outside the map \\[0.00, 6.00\\]",
    }
    for goal, reason in cases.items():
        result = planner.plan(world, (1.0, 2.0), goal)
        assert not result.ok and len(result.poses) == 0
        assert re.search(reason, result.reason), (goal, result.reason)


def test_robot_near_a_wall_plans_out_of_the_clearance():
    world = room()
    result = SimpleGridPlanner().plan(world, (0.45, 2.0), (4.0, 2.0, 0.0))
    assert result.ok, result.reason


def test_coarse_maps_are_used_as_they_are():
    world = SimpleMap(20, 10, 0.5)
    world.cells[:, 10] = True
    world.cells[9, 10] = False
    planner = SimpleGridPlanner(0.0, 0.0)
    assert planner.coarse_map(world) is world
    assert planner.plan(world, (1.0, 1.0), (9.0, 1.0, 0.0)).ok


@pytest.mark.parametrize(
    "goal", [(10.0, 2.0, 0.0), (1.0, 6.5, 1.57), (8.5, 6.0, 3.14), (6.0, -1.0, 0.0)]
)
def test_every_room_of_the_shipped_house_is_reachable_from_the_start(goal):
    home = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    result = SimpleGridPlanner().plan(home, (0.0, 0.0), goal)
    assert result.ok, result.reason
    assert clearance_along(home, result.poses[1:-1]) > 0.3


def test_bad_parameters_are_refused():
    with pytest.raises(ValueError, match="clearance_distance = -1"):
        SimpleGridPlanner(0.3, -1.0)


def pillars() -> SimpleMap:
    """Two pillars of the TurtleBot3 sandbox 1 m apart (0.4 x 0.35 m), in a 4 x 4 m room."""
    world = room(4.0, 4.0)
    world.cells[48:55, 47:55] = True   # x 2.35-2.75, y 2.40-2.75
    world.cells[49:56, 25:33] = True   # x 1.25-1.65, y 2.45-2.80
    return world


def test_a_start_in_a_pillars_clearance_leaves_it_without_passing_closer_to_the_next():
    # Where the sandbox's robot stood after turning at a waypoint, 0.28 m from a pillar: the
    # shortcut from its cell ran through the next pillar's clearance to 0.09 m of it (the
    # robot's radius is 0.15 m), and the robot following it hit the pillar.
    world = pillars()
    start = (2.12, 2.86)
    assert 0.2 < clearance_along(world, np.array([start, start])) < 0.3
    result = SimpleGridPlanner(0.15, 0.2).plan(world, start, (1.0, 1.0, 0.0))
    assert result.ok, result.reason
    assert clearance_along(world, result.poses) >= 0.25


def test_a_start_in_the_clearance_leaves_it_by_the_shortest_way_out():
    from easynav.planners.grid_astar import CLEARANCE, COLLISION, FREE, OBSTACLE

    # A wall along y = 0, its clearance in rows 1-3; the start in it, the goal far along it.
    levels = np.full((10, 30), FREE, dtype=np.int8)
    levels[0], levels[1], levels[2:4] = OBSTACLE, COLLISION, CLEARANCE
    cells = astar_8connected(levels, (2, 2), (27, 6))
    in_danger = [(x, y) for x, y in cells[1:] if levels[y, x] > FREE]
    assert in_danger == [cells[1]]  # one step out (the shortest path made 22 in the clearance)
