"""GridMap A* and RRT* without ROS: optimality, the slope rule, unreachable goals, determinism."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import (
    DiagnosticLevel,
    DiagnosticStatus,
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
)
from easynav.maps.gridmap import GridMap
from easynav.planners.gridmap.gridmap_astar_planner import GridMapAStarPlanner
from easynav.planners.gridmap.gridmap_rrtstar_planner import GridMapRRTStarPlanner
from easynav.planners.gridmap.terrain import (
    MARGIN_COST_FACTOR,
    body_cost_factors,
    cell_cost_factors,
    may_reach,
    slope_of_move,
    steep_cells,
    steep_within,
    terrain_regions,
)
from easynav.planners.gridmap.terrain_astar import astar, dijkstra_costs

_namespaces = itertools.count()
LIMIT_DEG = 30.0


def random_terrain(seed: int, size: int = 14, resolution: float = 0.1) -> GridMap:
    """Rough terrain: smoothed noise, steep enough that the rule cuts many moves."""
    rng = np.random.default_rng(seed)
    z = rng.normal(scale=0.08, size=(size, size))
    z = (z + np.roll(z, 1, 0) + np.roll(z, 1, 1)) / 2.0
    return GridMap.from_elevation(z, resolution, max_slope_rad=math.radians(LIMIT_DEG))


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("margin", [0.0, 0.15])
def test_astar_cost_equals_dijkstra_on_random_terrain(seed, margin):
    grid = random_terrain(seed)
    limit = math.radians(LIMIT_DEG)
    rng = np.random.default_rng(100 + seed)
    h, w = grid.shape
    start = (int(rng.integers(w)), int(rng.integers(h)))
    reference = dijkstra_costs(grid, start, limit, margin)
    reachable = 0
    for _ in range(8):
        goal = (int(rng.integers(w)), int(rng.integers(h)))
        found = astar(grid, start, goal, limit, margin)
        if math.isinf(reference[goal[1], goal[0]]):
            assert found is None
            continue
        reachable += 1
        cells, cost = found
        assert cost == pytest.approx(reference[goal[1], goal[0]], rel=1e-12, abs=1e-12)
        assert cells[0] == start and cells[-1] == goal
        assert_cells_obey_the_rule(grid, cells, limit)
    assert 0 < np.isinf(reference).sum() < reference.size  # the rule did cut something


@pytest.mark.parametrize("seed", range(12))
def test_regions_never_call_a_reachable_goal_unreachable(seed):
    # Checked against the Dijkstra from every start (steep starts too: the robot may be on one).
    grid = random_terrain(seed)
    limit = math.radians(LIMIT_DEG)
    regions = terrain_regions(grid, limit)
    h, w = grid.shape
    ruled_out = 0
    for start in itertools.product(range(0, w, 3), range(0, h, 3)):
        reachable = np.isfinite(dijkstra_costs(grid, start, limit))
        for gy, gx in itertools.product(range(h), range(w)):
            if not may_reach(regions, start, (gx, gy)):
                assert not reachable[gy, gx], (start, (gx, gy))
                ruled_out += 1
    assert ruled_out > 0  # and the regions do rule goals out


def test_a_walled_off_goal_is_unreachable_without_a_search(monkeypatch):
    # A flat yard inside a ring 2 m high (a building on a flat world's elevation map).
    z = np.zeros((60, 80))
    z[10:50, 30:70] = 2.0
    z[14:46, 34:66] = 0.0
    grid = GridMap.from_elevation(z, 0.1)
    regions = terrain_regions(grid, math.radians(LIMIT_DEG))
    assert not may_reach(regions, (5, 5), (50, 30))
    assert may_reach(regions, (5, 5), (75, 55))
    assert may_reach(regions, (50, 30), (50, 31))

    def no_search(*args, **kwargs):
        raise AssertionError("searched")

    from easynav.planners.gridmap import gridmap_astar_planner, gridmap_rrtstar_planner

    monkeypatch.setattr(gridmap_astar_planner, "astar", no_search)
    monkeypatch.setattr(gridmap_rrtstar_planner, "astar", no_search)
    for cls, params in PLANNERS:
        nav_state = state_with(grid, (0.5, 0.5), (5.0, 3.0, 0.0))
        make_planner(cls, params).update(nav_state)
        status = nav_state.get("diagnostics.path", DiagnosticStatus)
        assert status.level == DiagnosticLevel.WARN and "unreachable" in status.message


def assert_cells_obey_the_rule(grid, cells, limit):
    steep = steep_cells(grid, limit)
    z = grid.elevation
    for a, b in itertools.pairwise(cells):
        assert not steep[b[1], b[0]]
        assert max(abs(a[0] - b[0]), abs(a[1] - b[1])) == 1
        horizontal = grid.resolution * math.hypot(b[0] - a[0], b[1] - a[1])
        assert slope_of_move(z[a[1], a[0]], z[b[1], b[0]], horizontal) <= limit + 1e-9


def assert_path_obeys_the_rule(grid: GridMap, path: Path, limit: float) -> None:
    """Every cell a path crosses (sampled every 1/8 cell) and every step between them."""
    points = np.array([(p.x, p.y) for p in path.poses])
    steep = steep_cells(grid, limit)
    z = grid.elevation
    for a, b in itertools.pairwise(points):
        n = max(1, math.ceil(math.hypot(*(b - a)) / (grid.resolution / 8)))
        t = np.linspace(0, 1, n + 1)[:, None]
        ix, iy = grid.world_to_cell(*(a + t * (b - a)).T)
        cells = [c for i, c in enumerate(zip(ix, iy, strict=True))
                 if i == 0 or c != (ix[i - 1], iy[i - 1])]
        for c0, c1 in itertools.pairwise(cells):
            assert not steep[c1[1], c1[0]], f"steep cell {c1} used"
            horizontal = grid.resolution * math.hypot(c1[0] - c0[0], c1[1] - c0[1])
            slope = slope_of_move(z[c0[1], c0[0]], z[c1[1], c1[0]], horizontal)
            assert slope <= limit + 1e-9, f"move {c0}->{c1} at {math.degrees(slope):.1f} deg"


def ridge_world(gap: bool = True) -> GridMap:
    """8 m x 6 m, flat, split at x = 4 m by a 1 m wall (near-vertical sides); a 1 m gap at
    y 4..5 when ``gap``; a 35 deg cone hill (above the 30 deg limit) on the direct line."""
    resolution = 0.1
    xs = (np.arange(80) + 0.5) * resolution
    ys = (np.arange(60) + 0.5) * resolution
    x, y = np.meshgrid(xs, ys)
    z = np.zeros_like(x)
    z[(x > 3.8) & (x < 4.2)] = 1.0
    if gap:
        z[(x > 3.7) & (x < 4.3) & (y > 4.0) & (y < 5.0)] = 0.0
    r = np.hypot(x - 2.0, y - 2.0)
    z += np.clip(math.tan(math.radians(35)) * (0.8 - r), 0.0, None)
    return GridMap.from_elevation(z, resolution)


def make_planner(cls, params=None):
    planner = cls()
    planner.initialize(
        PluginContext(
            parameters=DictParameters({f"p.{k}": v for k, v in (params or {}).items()}),
            namespace=f"gridmap_planner_test_{next(_namespaces)}",
            now=lambda: 2.0,
        ),
        "p",
    )
    return planner


def state_with(grid, start, goal) -> NavState:
    nav_state = NavState()
    nav_state.set("map", grid)
    nav_state.set("robot_pose",
                  Odometry(Header(1.0, "map"), "base_footprint", Pose.from_xy_yaw(*start, 0.0)))
    pose = PoseStamped(Header(1.0, "map"), Pose.from_xy_yaw(*goal))
    nav_state.set("goals", Goals(Header(1.0, "map"), [pose]))
    return nav_state


PLANNERS = [
    (GridMapAStarPlanner, {"max_allowed_slope_deg": LIMIT_DEG}),
    (GridMapRRTStarPlanner, {"max_allowed_slope_deg": LIMIT_DEG, "seed": 3}),
]


@pytest.mark.parametrize(("cls", "params"), PLANNERS)
def test_planners_go_round_the_steep_hill_and_through_the_gap(cls, params):
    grid = ridge_world()
    planner = make_planner(cls, params)
    nav_state = state_with(grid, (1.0, 1.0), (7.0, 1.0, 0.5))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert len(path) > 1
    assert_path_obeys_the_rule(grid, path, math.radians(LIMIT_DEG))
    ys_at_wall = [p.y for p in path.poses if 3.7 < p.x < 4.3]
    assert ys_at_wall and all(4.0 < yy < 5.0 for yy in ys_at_wall)
    assert (path.poses[-1].x, path.poses[-1].y) == pytest.approx((7.0, 1.0))
    assert path.poses[-1].yaw == pytest.approx(0.5)
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.level == DiagnosticLevel.OK


@pytest.mark.parametrize(("cls", "params"), PLANNERS)
def test_a_slope_just_above_the_limit_is_never_climbed(cls, params):
    """A plateau reached only by a 31 deg ramp: unreachable at 30 deg, reachable at 32."""
    resolution = 0.1
    x = (np.arange(60) + 0.5) * resolution
    profile = np.clip(math.tan(math.radians(31)) * (x - 2.0), 0.0, 1.0)
    grid = GridMap.from_elevation(np.tile(profile, (20, 1)), resolution)
    nav_state = state_with(grid, (0.5, 1.0), (5.5, 1.0, 0.0))
    make_planner(cls, params).update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.level == DiagnosticLevel.WARN and "unreachable" in status.message
    steeper = dict(params, max_allowed_slope_deg=32.0)
    make_planner(cls, steeper).update(nav_state)
    path = nav_state.get("path", Path)
    assert len(path) > 1
    assert_path_obeys_the_rule(grid, path, math.radians(32.0))


@pytest.mark.parametrize(("cls", "params"), PLANNERS)
def test_unreachable_goal_gives_an_empty_path_and_a_warning(cls, params):
    nav_state = state_with(ridge_world(gap=False), (1.0, 1.0), (7.0, 1.0, 0.0))
    make_planner(cls, params).update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.level == DiagnosticLevel.WARN
    assert "goal (7.00, 1.00)" in status.message and "unreachable" in status.message


@pytest.mark.parametrize(("cls", "params"), PLANNERS)
def test_goal_off_the_map_or_on_the_hill_is_rejected_naming_why(cls, params):
    # Never reachable on this map: rejected (the goal client gets the reason, NAVIGATION_FAILED).
    planner = make_planner(cls, params)
    for goal, reason in (
        ((9.0, 1.0), "goal (9.00, 1.00) is off the gridmap (x 0..8, y 0..6)"),
        ((2.3, 2.3), "goal (2.30, 2.30) is on terrain steeper than 30 deg or unknown"),
    ):
        nav_state = state_with(ridge_world(), (1.0, 1.0), (*goal, 0.0))
        planner.update(nav_state)
        assert nav_state.get("diagnostics.path", DiagnosticStatus).message == reason
        assert planner.take_goal_rejection() == reason
        assert len(nav_state.get("path", Path)) == 0


@pytest.mark.parametrize(("cls", "params"), PLANNERS)
def test_a_robot_off_the_map_gets_no_path_and_its_goal_is_kept(cls, params):
    # Where the robot is may change (a localizer settling): the recovery system decides.
    planner = make_planner(cls, params)
    nav_state = state_with(ridge_world(), (20.0, 1.0), (1.0, 1.0, 0.0))
    planner.update(nav_state)
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.level == DiagnosticLevel.WARN
    assert status.message == "robot (20.00, 1.00) is off the gridmap (x 0..8, y 0..6)"
    assert planner.take_goal_rejection() is None


def test_rrtstar_is_deterministic_for_a_seed():
    grid = ridge_world()
    paths = []
    for _ in range(2):
        nav_state = state_with(grid, (1.0, 1.0), (7.0, 1.0, 0.0))
        make_planner(GridMapRRTStarPlanner, {"seed": 11, "max_iters": 1500}).update(nav_state)
        paths.append([(p.x, p.y, p.yaw) for p in nav_state.get("path", Path).poses])
    assert paths[0] and paths[0] == paths[1]


def test_rrtstar_output_spacing_and_goal_orientation():
    nav_state = state_with(ridge_world(), (1.0, 5.5), (7.0, 5.5, 1.0))
    make_planner(GridMapRRTStarPlanner, {"spacing": 0.3, "final_poses_with_goal_orientation": 3,
                                         "max_iters": 1500}).update(nav_state)
    poses = nav_state.get("path", Path).poses
    gaps = np.hypot(np.diff([p.x for p in poses]), np.diff([p.y for p in poses]))
    assert gaps.max() <= 0.3 + 1e-9
    assert [p.yaw for p in poses[-3:]] == pytest.approx([1.0] * 3)


def test_margin_cells_cost_more_and_steep_cells_are_infinite():
    grid = ridge_world()
    factors = cell_cost_factors(grid, math.radians(LIMIT_DEG), 0.3)
    steep = steep_cells(grid, math.radians(LIMIT_DEG))
    assert np.isinf(factors[steep]).all() and np.isfinite(factors[~steep]).all()
    assert (factors[~steep] > 1).any()


@pytest.mark.parametrize(("cls", "params"), PLANNERS)
def test_shipped_uneven_world_plateau_only_by_the_ramp(cls, params):
    """easynav_maps' worlds/uneven_terrain.yaml (the original's format): the plateau (0.8 m)
    has 60 deg cliffs and one 15 deg ramp at y 1..3 m."""
    from easynav.maps import resolve_map_file
    from easynav.maps.gridmap import load_gridmap

    grid = load_gridmap(resolve_map_file("easynav_maps", "worlds/uneven_terrain.yaml"))
    nav_state = state_with(grid, (1.0, 6.5), (10.0, 6.0, 0.0))
    make_planner(cls, params).update(nav_state)
    path = nav_state.get("path", Path)
    assert len(path) > 1, nav_state.get("diagnostics.path", DiagnosticStatus).message
    assert_path_obeys_the_rule(grid, path, math.radians(LIMIT_DEG))
    climb = [p.y for p in path.poses if 5.0 < p.x < 7.4]
    z = grid.elevation
    ix, iy = grid.world_to_cell(np.array([p.x for p in path.poses]),
                                np.array([p.y for p in path.poses]))
    on_slope = (z[iy, ix] > 0.05) & (z[iy, ix] < 0.75)
    assert on_slope.any() and climb
    ys = np.array([p.y for p in path.poses])[on_slope]
    assert ((ys > 1.0) & (ys < 3.0)).all()  # climbed on the ramp only


def _poses(nav_state):
    return [(p.x, p.y, p.yaw) for p in nav_state.get("path", Path).poses]


def _move_robot(nav_state, x, y):
    nav_state.set("robot_pose",
                  Odometry(Header(2.0, "map"), "base_footprint", Pose.from_xy_yaw(x, y, 0.0)))


def _rrtstar_on_the_ridge(start=(1.0, 1.0)):
    """An RRT* planner and a NavState on :func:`ridge_world`, the goal at (7, 1)."""
    planner = make_planner(GridMapRRTStarPlanner, {"seed": 5, "max_iters": 1500})
    return planner, state_with(ridge_world(), start, (7.0, 1.0, 0.0))


def test_rrtstar_keeps_its_path_while_the_robot_follows_it():
    # A new random tree from every pose the robot passes would give a new path every cycle.
    planner, nav_state = _rrtstar_on_the_ridge()
    planner.update(nav_state)
    first = _poses(nav_state)
    assert len(first) > 10
    # Along the path, and 0.4 m beside it (max_lateral_deviation 0.5): the same path (a
    # quarter of the way, on open ground: half way is the ridge's gap, 0.7 m beside it the wall).
    x, y, yaw = first[len(first) // 4]
    for robot in ((x, y), (x - 0.4 * math.sin(yaw), y + 0.4 * math.cos(yaw))):
        _move_robot(nav_state, *robot)
        planner.update(nav_state)
        assert _poses(nav_state) == first
    # 0.7 m beside it: planned again from where the robot is.
    rx, ry = x - 0.7 * math.sin(yaw), y + 0.7 * math.cos(yaw)
    _move_robot(nav_state, rx, ry)
    planner.update(nav_state)
    replanned = _poses(nav_state)
    assert replanned != first
    assert replanned[0][:2] == pytest.approx((rx, ry))
    assert replanned[-1] == pytest.approx((7.0, 1.0, 0.0))


def test_rrtstar_plans_again_for_a_new_goal_map_or_parameter():
    planner, nav_state = _rrtstar_on_the_ridge()
    grid = nav_state.get("map")
    planner.update(nav_state)
    first = _poses(nav_state)
    # The same goal with another yaw is another goal.
    pose = PoseStamped(Header(1.0, "map"), Pose.from_xy_yaw(7.0, 1.0, 1.0))
    nav_state.set("goals", Goals(Header(1.0, "map"), [pose]))
    planner.update(nav_state)
    assert _poses(nav_state)[-1] == pytest.approx((7.0, 1.0, 1.0))
    # A new map (GridmapMapsManager.set_map), here with the gap closed: planned on it.
    nav_state.set("map", ridge_world(gap=False))
    planner.update(nav_state)
    assert _poses(nav_state) == []
    assert "unreachable" in nav_state.get("diagnostics.path", DiagnosticStatus).message
    nav_state.set("map", grid)
    planner.update(nav_state)
    assert len(_poses(nav_state)) > 10
    # A parameter changed at runtime: planned with it.
    planner.apply_parameter("spacing", 0.1)
    planner.update(nav_state)
    gaps = np.hypot(*np.diff(np.array(_poses(nav_state))[:, :2], axis=0).T)
    assert gaps.max() <= 0.1 + 1e-9 and len(_poses(nav_state)) > len(first)


def test_distance_to_polyline_matches_a_dense_sampling():
    from easynav.planners.gridmap.gridmap_rrtstar_planner import distance_to_polyline

    rng = np.random.default_rng(4)
    for _ in range(50):
        points = rng.uniform(-3, 3, size=(int(rng.integers(1, 6)), 2))
        xy = tuple(rng.uniform(-4, 4, size=2))
        if len(points) == 1:
            dense = points
        else:
            t = np.linspace(0.0, 1.0, 4001)[:, None]
            pairs = zip(points[:-1], points[1:], strict=True)
            dense = np.concatenate([a + t * (b - a) for a, b in pairs])
        expected = np.hypot(*(dense - np.array(xy)).T).min()
        assert distance_to_polyline(points, xy) == pytest.approx(expected, abs=2e-3)


def test_rrtstar_drops_its_path_when_the_robot_leaves_the_map():
    planner, nav_state = _rrtstar_on_the_ridge(start=(0.3, 1.0))
    planner.update(nav_state)
    assert len(_poses(nav_state)) > 10
    _move_robot(nav_state, -0.2, 1.0)  # 0.5 m from the path's start, off the map
    planner.update(nav_state)
    assert _poses(nav_state) == []
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.message.startswith("robot (-0.20, 1.00) is off the gridmap")


def test_rrtstar_does_not_keep_a_path_planned_before_a_parameter_change():
    # The parameter thread changes spacing while the non-RT thread plans.
    planner, nav_state = _rrtstar_on_the_ridge()
    plan = planner.plan

    def plan_meanwhile_changed(*args):
        result = plan(*args)
        planner.apply_parameter("spacing", 0.1)
        return result

    planner.plan = plan_meanwhile_changed
    planner.update(nav_state)
    planner.plan = plan
    planner.update(nav_state)
    gaps = np.hypot(*np.diff(np.array(_poses(nav_state))[:, :2], axis=0).T)
    assert gaps.max() <= 0.1 + 1e-9


def test_astar_margin_takes_the_radius_of_robot_geometry(caplog):
    # The seed: the planner's own robot_radius is a deprecated copy; robot_geometry takes
    # precedence where it sets the radius.
    from easynav.core.robot import RobotGeometry

    def astar_planner(params, geometry):
        planner = GridMapAStarPlanner()
        planner.initialize(
            PluginContext(parameters=DictParameters({f"p.{k}": v for k, v in params.items()}),
                          namespace=f"gridmap_planner_test_{next(_namespaces)}",
                          robot_geometry=lambda: geometry),
            "p",
        )
        return planner

    configured = RobotGeometry(radius=0.45, inscribed_radius=0.45, user_set=frozenset({"radius"}))
    assert astar_planner({}, configured).robot_radius() == 0.45
    assert astar_planner({"robot_radius": 0.2}, configured).robot_radius() == 0.45
    assert "p.robot_radius is deprecated and ignored" in caplog.text
    assert astar_planner({"robot_radius": 0.2}, RobotGeometry()).robot_radius() == 0.2
    assert astar_planner({}, RobotGeometry()).robot_radius() == 0.3  # the original's default


def _margin_cells_crossed(grid, path, radius, robot):
    """The cells within ``radius`` of steep terrain (centre to centre) a path crosses (sampled
    every 1/8 cell), leaving out those the planner opens around ``robot``."""
    margin = cell_cost_factors(grid, math.radians(LIMIT_DEG), radius) == MARGIN_COST_FACTOR
    points = np.array([(p.x, p.y) for p in path.poses])
    reopened = math.sqrt(2) * (radius + grid.resolution) + grid.resolution
    crossed = set()
    for a, b in itertools.pairwise(points):
        n = max(1, math.ceil(math.hypot(*(b - a)) / (grid.resolution / 8)))
        t = np.linspace(0, 1, n + 1)[:, None]
        for x, y in a + t * (b - a):
            ix, iy = (int(v) for v in grid.world_to_cell(x, y))
            if margin[iy, ix] and math.hypot(x - robot[0], y - robot[1]) > reopened:
                crossed.add((ix, iy))
    return crossed


@pytest.mark.parametrize("seed", range(6))
def test_rrtstar_paths_keep_the_robots_body_off_steep_terrain(seed):
    # Priced rather than closed, the margin was cut through wherever that was shorter: on the
    # campus, RRT* paths rounded buildings with 0.01 m between the robot and the wall.
    grid = ridge_world()
    for start, goal in (((1.0, 1.0), (7.0, 1.0)), ((1.0, 5.5), (7.0, 5.5)),
                        ((3.0, 0.6), (6.0, 5.7))):
        nav_state = state_with(grid, start, (*goal, 0.0))
        make_planner(GridMapRRTStarPlanner, {"seed": seed, "max_iters": 1500,
                                             "max_allowed_slope_deg": LIMIT_DEG}).update(nav_state)
        path = nav_state.get("path", Path)
        assert len(path) > 1, nav_state.get("diagnostics.path", DiagnosticStatus).message
        assert not _margin_cells_crossed(grid, path, 0.3, start), (start, goal)


def test_rrtstar_leaves_the_margin_it_starts_in_and_refuses_a_goal_inside_it():
    grid = ridge_world()
    start = (3.6, 1.0)  # 0.2 m from the wall's foot (x 3.8): the robot's circle touches it
    assert cell_cost_factors(grid, math.radians(LIMIT_DEG), 0.3)[
        tuple(int(v) for v in reversed(grid.world_to_cell(*start)))] == MARGIN_COST_FACTOR
    nav_state = state_with(grid, start, (1.0, 5.5, 0.0))
    planner = make_planner(GridMapRRTStarPlanner,
                           {"max_iters": 1500, "max_allowed_slope_deg": LIMIT_DEG})
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert len(path) > 1 and not _margin_cells_crossed(grid, path, 0.3, start)
    # A goal the robot's circle cannot reach without touching the wall: refused, saying so.
    nav_state = state_with(grid, (1.0, 5.5), (3.6, 1.0, 0.0))
    planner.update(nav_state)
    reason = ("goal (3.60, 1.00) is within the robot's radius (0.30 m) of terrain steeper than "
              "30 deg or unknown")
    assert nav_state.get("diagnostics.path", DiagnosticStatus).message == reason
    assert planner.take_goal_rejection() == reason


def test_body_cost_factors_close_the_margin_except_around_the_robot():
    grid = ridge_world()
    limit = math.radians(LIMIT_DEG)
    priced = cell_cost_factors(grid, limit, 0.3)
    robot = (36, 10)  # (3.65, 1.05): in the margin of the wall's foot
    factors = body_cost_factors(grid, limit, 0.3, robot)
    steep = steep_cells(grid, limit)
    assert np.isinf(factors[steep]).all()
    assert (factors[priced == 1.0] == 1.0).all()
    margin = priced == MARGIN_COST_FACTOR
    iy, ix = np.nonzero(margin)
    near = np.hypot(ix - robot[0], iy - robot[1]) <= math.sqrt(2) * (0.3 / grid.resolution + 1) + 1
    assert near.any() and (~near).any()
    assert (factors[iy[near], ix[near]] == MARGIN_COST_FACTOR).all()
    assert np.isinf(factors[iy[~near], ix[~near]]).all()


def test_steep_within_is_the_margin_rule_for_one_cell():
    grid = ridge_world()
    limit = math.radians(LIMIT_DEG)
    for radius in (0.0, 0.25, 0.3):
        factors = cell_cost_factors(grid, limit, radius)
        h, w = grid.shape
        within = np.array([[steep_within(grid, ix, iy, radius, limit) for ix in range(w)]
                           for iy in range(h)])
        assert (within == (factors > 1.0)).all(), radius


@pytest.mark.parametrize("offset", [-0.03, 0.0, 0.03, 0.05, 0.08])
def test_rrtstar_leaves_an_inside_corner_it_starts_in(offset):
    # From a corner, the nearest cell out of the margin is on the diagonal: a disc of the
    # margin's width around the robot left it shut in ("unreachable").
    resolution = 0.05
    xs = (np.arange(160) + 0.5) * resolution
    x, y = np.meshgrid(xs, xs)
    grid = GridMap.from_elevation(np.where((x < 1.0) | (y < 1.0), 2.0, 0.0), resolution)
    start = (1.05 + offset, 1.05 + offset)
    nav_state = state_with(grid, start, (6.0, 6.0, 0.0))
    make_planner(GridMapRRTStarPlanner, {"max_iters": 1500}).update(nav_state)
    assert len(nav_state.get("path", Path)) > 1, (
        nav_state.get("diagnostics.path", DiagnosticStatus).message)
