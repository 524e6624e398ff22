"""CostmapPlanner without ROS: NavState in and out, unreachable goals, replanning, stamps."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.types import (
    Costmap2D,
    DiagnosticLevel,
    DiagnosticStatus,
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
)
from easynav.maps.inflation import inflate
from easynav.planners.costmap_astar import BLOCKED_COST
from easynav.planners.costmap_planner import (
    CostmapPlanner,
    leaves_ahead,
    smooth_path,
    uninflated,
    without_cells_behind,
)

_namespaces = itertools.count()


def room() -> Costmap2D:
    """8 x 4 m at 0.05 m, walls around, a wall at x = 4 m with a door at y 2.4..3.6, the wall
    inflated by 0.25 m (253) and graded costs up to 0.5 m."""
    data = np.zeros((80, 160), dtype=np.uint8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 254
    data[0:48, 80:82] = 254
    data[72:80, 80:82] = 254
    # Inflate with the original's formula (inscribed 0.25 m, k = 3) via brute force distances.
    walls = np.argwhere(data == 254)
    yy, xx = np.mgrid[0:80, 0:160]
    dist = np.full(data.shape, np.inf)
    for y, x in walls:
        dist = np.minimum(dist, np.hypot(yy - y, xx - x) * 0.05)
    graded = np.where(dist <= 0.25, 253, np.floor(252 * np.exp(-3.0 * (dist - 0.25))))
    graded[dist > 0.5] = 0
    data = np.maximum(data, graded.astype(np.uint8))
    return Costmap2D(data, 0.05, 0.0, 0.0, "map", 4.5)


def make_planner(params=None) -> CostmapPlanner:
    context = PluginContext(
        parameters=DictParameters({f"costmap.{k}": v for k, v in (params or {}).items()}),
        namespace=f"costmap_planner_test_{next(_namespaces)}",
        now=lambda: 7.0,
    )
    planner = CostmapPlanner()
    planner.initialize(context, "costmap")
    return planner


def state_with(goal, robot_xy=(1.0, 1.0), frame="map", costmap=None, robot_yaw=0.0) -> NavState:
    nav_state = NavState()
    costmap = costmap or room()
    nav_state.set("map", costmap)
    nav_state.set("map.base", costmap)
    nav_state.set("map_time", 4.5)
    nav_state.set(
        "robot_pose",
        Odometry(Header(3.0, "map"), "base_footprint", Pose.from_xy_yaw(*robot_xy, robot_yaw)),
    )
    g = PoseStamped(Header(5.0, frame), Pose.from_xy_yaw(*goal))
    nav_state.set("goals", Goals(Header(5.0, frame), [g]))
    return nav_state


def diagnostic(nav_state) -> DiagnosticStatus:
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.hardware_id == "planner"
    return status


def xy(path: Path) -> np.ndarray:
    return np.array([[p.x, p.y] for p in path.poses])


def test_plans_through_the_door_and_ends_at_the_goal_pose():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 1.5))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert path.header.frame_id == "map" and path.header.stamp == 4.5  # map_time
    points = xy(path)
    assert points[-1] == pytest.approx([7.0, 1.0])
    assert path.poses[-1].yaw == pytest.approx(1.5)
    # It crosses the wall through the door, never through the inscribed zone.
    costs = room().cost_at(points[:, 0], points[:, 1])
    assert (costs < 253).all()
    crossing = points[np.argmin(np.abs(points[:, 0] - 4.05))]
    assert 2.4 < crossing[1] < 3.6
    # Consecutive poses are about one cell apart; each faces the next.
    steps = np.hypot(*np.diff(points, axis=0).T)
    assert steps.max() < 0.1
    heading = np.arctan2(*np.diff(points, axis=0)[:3].T[::-1])
    assert [p.yaw for p in path.poses[:3]] == pytest.approx(list(heading))
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.OK and "path of" in status.message


def test_a_blocked_route_gives_an_empty_path_and_a_warning_not_the_goal():
    costmap = room()
    costmap.data[48:72, 80:82] = 254  # the door closed by a live obstacle
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0), costmap=costmap)
    nav_state.set("map.base", room())  # the static map still has the door
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.WARN
    assert "no route from (1.00, 1.00) to goal (7.00, 1.00)" in status.message
    assert planner.take_goal_rejection() is None  # the recovery system decides


@pytest.mark.parametrize(
    ("goal", "reason"),
    [
        ((20.0, 1.0, 0.0), "is off the map [0.00, 8.00] x [0.00, 4.00]"),
        ((4.02, 1.0, 0.0), "is on an obstacle of the static map"),
    ],
)
def test_goals_that_can_never_be_reached_are_rejected(goal, reason):
    planner = make_planner()
    nav_state = state_with(goal)
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert reason in diagnostic(nav_state).message
    assert reason in planner.take_goal_rejection()


def test_a_goal_in_the_inflated_zone_is_reported_with_its_cost():
    planner = make_planner()
    nav_state = state_with((3.9, 1.0, 0.0))
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert "inside the inflated zone of an obstacle (cost 253)" in diagnostic(nav_state).message


def test_a_goal_in_another_frame_is_rejected():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0), frame="odom")
    planner.update(nav_state)
    assert "is in frame 'odom', not 'map'" in planner.take_goal_rejection()


def test_cost_factor_keeps_the_path_off_graded_cells():
    near, far = [], []
    for factor, out in ((0.0, near), (5.0, far)):
        # Through the door (y 2.4..3.6) from below its middle: the shortest way grazes the
        # graded cells at the door's lower edge.
        nav_state = state_with((7.0, 2.0, 0.0), robot_xy=(1.0, 2.0))
        make_planner({"cost_factor": factor}).update(nav_state)
        points = xy(nav_state.get("path", Path))
        out.append(room().cost_at(points[:, 0], points[:, 1]).astype(float).sum())
    assert far[0] < near[0]


def test_without_continuous_replan_the_path_is_kept_until_blocked():
    planner = make_planner({"continuous_replan": False})
    nav_state = state_with((7.0, 1.0, 0.0))
    planner.update(nav_state)
    first = nav_state.get("path", Path)
    moved = Pose.from_xy_yaw(1.5, 1.2, 0.0)
    nav_state.set("robot_pose", Odometry(Header(4.0, "map"), "base_footprint", moved))
    planner.update(nav_state)
    assert nav_state.get("path", Path) is first  # kept: same goal, nothing blocked
    blocked = room()
    points = xy(first)
    ix, iy = blocked.world_to_cell(points[len(points) // 2, 0], points[len(points) // 2, 1])
    blocked.data[iy - 2 : iy + 3, ix - 2 : ix + 3] = 254
    nav_state.set("map", blocked)
    planner.update(nav_state)
    replanned = nav_state.get("path", Path)
    assert replanned is not first and len(replanned) > 0


def test_no_goal_writes_an_empty_path_and_bad_parameters_fail_configure():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0))
    nav_state.set("goals", Goals(Header(5.0, "map"), []))
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    with pytest.raises(PluginConfigurationError, match="costmap.heuristic_scale"):
        make_planner({"heuristic_scale": 0.0})


def test_smoothing_keeps_the_ends_and_straight_lines():
    line = np.column_stack((np.arange(10.0), np.zeros(10)))
    assert smooth_path(line) == pytest.approx(line)
    corner = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [2, 2]], dtype=float)
    smoothed = smooth_path(corner)
    assert smoothed[0] == pytest.approx([0, 0]) and smoothed[-1] == pytest.approx([2, 2])
    assert smoothed[2] == pytest.approx([1.4, 0.6])  # the corner is cut


def pillar_room() -> Costmap2D:
    """2 x 2 m at 0.05 m with a lethal 0.4 m pillar in the middle: from one corner to the
    opposite one the two detours around the pillar cost the same."""
    data = np.zeros((40, 40), dtype=np.uint8)
    data[16:24, 16:24] = 254
    return Costmap2D(data, 0.05, 0.0, 0.0, "map", 4.5)


def side_of_pillar(path: Path) -> str:
    """Which detour a path takes: above or below the diagonal through the pillar."""
    points = xy(path)
    middle = points[np.argmin(np.hypot(points[:, 0] - 1.0, points[:, 1] - 1.0))]
    return "above" if middle[1] > middle[0] else "below"


def one_side(costmap: Costmap2D, side: str) -> np.ndarray:
    """The free cells strictly above or below the diagonal."""
    rows, cols = np.indices(costmap.data.shape)
    return ((rows > cols) if side == "above" else (rows < cols)) & (costmap.data == 0)


def sides_while_the_robot_wobbles(hysteresis: float) -> list[str]:
    """The detour planned at each step of a robot that wobbles by a cell across the diagonal
    near the start corner (as a controller does when it hesitates between two routes)."""
    planner = make_planner({"replan_hysteresis": hysteresis})
    sides = []
    for dx, dy in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 2), (3, 1), (2, 3)):
        robot = (0.225 + 0.05 * dx, 0.225 + 0.05 * dy)
        nav_state = state_with((1.775, 1.775, 0.0), robot_xy=robot, costmap=pillar_room())
        planner.update(nav_state)
        sides.append(side_of_pillar(nav_state.get("path", Path)))
    return sides


def test_the_cheapest_path_every_cycle_flips_between_equal_detours():
    # The original's behaviour (replan_hysteresis 0): a one-cell wobble flips the route.
    assert len(set(sides_while_the_robot_wobbles(0.0))) == 2


def test_the_previous_route_is_kept_while_it_costs_about_the_same():
    sides = sides_while_the_robot_wobbles(0.1)  # the default
    assert len(set(sides)) == 1
    planner = make_planner()
    assert planner.params.replan_hysteresis == pytest.approx(0.1)


def test_the_previous_route_gives_way_when_blocked_or_much_dearer():
    planner = make_planner()
    robot = (0.225, 0.225)
    nav_state = state_with((1.775, 1.775, 0.0), robot_xy=robot, costmap=pillar_room())
    planner.update(nav_state)
    first = side_of_pillar(nav_state.get("path", Path))
    # Graded cost (not blocking) over the first detour: dearer by far more than 10 %.
    dear = pillar_room()
    dear.data[one_side(dear, first)] = 200
    nav_state = state_with((1.775, 1.775, 0.0), robot_xy=robot, costmap=dear)
    planner.update(nav_state)
    second = side_of_pillar(nav_state.get("path", Path))
    assert second != first
    # Now block the second detour: the route switches back although it was kept before.
    blocked = pillar_room()
    blocked.data[one_side(blocked, second)] = 254
    nav_state = state_with((1.775, 1.775, 0.0), robot_xy=robot, costmap=blocked)
    planner.update(nav_state)
    assert side_of_pillar(nav_state.get("path", Path)) == first


def pillar_grid() -> Costmap2D:
    """4.4 m square at 0.05 m, pillars of 0.15 m radius 1.1 m apart (the TurtleBot3 sandbox's
    layout), inflated as the costmap stack does (0.7 m, k = 3, inscribed 0.15 m). From the
    middle of one square of pillars to the middle of the next one diagonally, the routes up
    then right and right then up cost the same."""
    yy, xx = (np.indices((88, 88)) + 0.5) * 0.05
    data = np.zeros((88, 88), dtype=np.uint8)
    for px, py in itertools.product((1.1, 2.2, 3.3), repeat=2):
        data[np.hypot(xx - px, yy - py) <= 0.15] = 254
    return Costmap2D(inflate(data, 0.05, 0.7, 0.15, 3.0), 0.05, 0.0, 0.0, "map", 4.5)


def first_move(path: Path, start=(1.65, 1.65)) -> str:
    """"up" or "right": where the path is when it is 0.4 m from the start."""
    points = xy(path)
    far = points[np.hypot(points[:, 0] - start[0], points[:, 1] - start[1]) >= 0.4][0]
    return "up" if far[1] - start[1] > far[0] - start[0] else "right"


@pytest.mark.parametrize(("robot_yaw", "move"), [(np.pi / 2, "up"), (0.0, "right")])
def test_of_two_equal_routes_the_robot_takes_the_one_it_faces(robot_yaw, move):
    # At a waypoint the robot faces its yaw; the next goal lies beyond a pillar with a route on
    # either side. The one ahead is taken: turning towards the other, the robot would drift
    # between the two and have the path flip back under it beside the pillar.
    planner = make_planner()
    nav_state = state_with((2.75, 2.75, 0.0), robot_xy=(1.65, 1.65), costmap=pillar_grid(),
                           robot_yaw=robot_yaw)
    planner.update(nav_state)
    assert first_move(nav_state.get("path", Path)) == move


def test_the_route_ahead_is_kept_while_the_robot_turns():
    planner = make_planner()
    for robot_yaw in (np.pi / 2, 0.8, 0.3):  # a controller hesitating between the two
        nav_state = state_with((2.75, 2.75, 0.0), robot_xy=(1.65, 1.65), costmap=pillar_grid(),
                               robot_yaw=robot_yaw)
        planner.update(nav_state)
        assert first_move(nav_state.get("path", Path)) == "up"


def test_a_robot_facing_away_from_a_much_cheaper_path_turns_round():
    # The goal is behind the robot: going ahead first would cost far more than 10 % extra, so
    # the path leaves behind the robot.
    planner = make_planner()
    nav_state = state_with((1.0, 3.0, 0.0), robot_xy=(3.0, 3.0), robot_yaw=0.0)
    planner.update(nav_state)
    points = xy(nav_state.get("path", Path))
    assert (points[:, 0] <= 3.0 + 1e-9).all()


def test_without_hysteresis_the_heading_is_ignored_as_in_the_original():
    moves = set()
    for robot_yaw in (np.pi / 2, 0.0):
        planner = make_planner({"replan_hysteresis": 0.0})
        nav_state = state_with((2.75, 2.75, 0.0), robot_xy=(1.65, 1.65), costmap=pillar_grid(),
                               robot_yaw=robot_yaw)
        planner.update(nav_state)
        moves.add(first_move(nav_state.get("path", Path)))
    assert len(moves) == 1


def test_leaves_ahead_and_the_blocked_cells_agree():
    costs = np.zeros((20, 20), dtype=np.uint8)
    masked = without_cells_behind(costs, (10, 10), np.pi / 2, 6)
    assert masked[10, 10] == 0  # the robot's cell
    assert masked[16, 10] == 0 and masked[14, 13] == 0  # ahead (up), 37 degrees off
    assert masked[10, 16] == BLOCKED_COST and masked[4, 10] == BLOCKED_COST  # right, behind
    assert masked[10, 17] == 0  # beyond the radius
    up = np.array([[10, 10], [10, 11], [11, 12], [12, 13], [13, 14], [14, 15], [15, 16]])
    right = np.array([[10, 10], [11, 10], [12, 11], [13, 11]])
    assert leaves_ahead(up, np.pi / 2, 6) and not leaves_ahead(right, np.pi / 2, 6)


def test_a_costmap_without_inflation_is_warned_about_once(caplog):
    # The planner keeps off cells of cost >= 253 only: on a costmap without the inscribed band
    # of an inflation filter its paths graze the walls, and the user is told why.
    bare = room()
    bare.data[(bare.data > 0) & (bare.data < 254)] = 0
    empty = Costmap2D(np.zeros_like(bare.data), 0.05, 0.0, 0.0, "map", 4.5)
    planner = make_planner()
    with caplog.at_level("WARNING", logger="easynav"):
        planner.update(state_with((7.0, 1.0, 0.0), costmap=empty))  # nothing to tell yet
        assert "InflationFilter" not in caplog.text
        for _ in range(3):
            planner.update(state_with((7.0, 1.0, 0.0), costmap=bare))
    warnings = [r.getMessage() for r in caplog.records if "InflationFilter" in r.getMessage()]
    assert len(warnings) == 1
    assert "no inscribed cells (cost 253)" in warnings[0]
    assert "robot's radius" in warnings[0]


def test_an_inflated_costmap_is_not_warned_about(caplog):
    planner = make_planner()
    with caplog.at_level("WARNING", logger="easynav"):
        planner.update(state_with((7.0, 1.0, 0.0)))
    assert "InflationFilter" not in caplog.text
    assert uninflated(room().data) is False
    assert uninflated(np.zeros((3, 3), np.uint8)) is None


def test_on_a_map_coarser_than_the_robot_graded_costs_are_inflation_enough():
    # Inscribed radius 0.25 m on 0.3 m cells: an inflation filter raises no cell to 253, only
    # grades them. Graded cells mean a filter ran; none at all mean none did.
    walls = np.zeros((20, 20), np.uint8)
    walls[10, :] = 254
    graded = walls.copy()
    graded[9, :] = graded[11, :] = 120
    assert uninflated(graded, band_cells=True) is True
    assert uninflated(graded, band_cells=False) is False
    assert uninflated(walls, band_cells=False) is True
