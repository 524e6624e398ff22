"""NavMapAStarPlanner without ROS: optimal costs against Dijkstra, two floors, slopes, costs,
smoothing on the surface."""

from __future__ import annotations

import heapq
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
from easynav.maps.navmap import NavMap
from easynav.planners.navmap_astar import (
    astar_navmap,
    astar_navmap_reference,
    compiled_available,
    path_cost,
    step_multipliers,
)
from easynav.planners.navmap_planner import (
    NavMapAStarPlanner,
    clamp_to_triangles,
    smooth_on_navcels,
)
from easynav.planners.navmap_shortcut import shortcut_path, walk_segment

_namespaces = itertools.count()
RES = 0.1


# -- meshes --------------------------------------------------------------------------
def patch(x0, x1, y0, y1, z=lambda x, y: 0.0 * x, res=RES):
    """Vertices and faces of a quad grid over [x0, x1] x [y0, y1] with height z(x, y)."""
    nx, ny = round((x1 - x0) / res), round((y1 - y0) / res)
    xs, ys = np.linspace(x0, x1, nx + 1), np.linspace(y0, y1, ny + 1)
    xx, yy = np.meshgrid(xs, ys)
    vertices = np.column_stack([xx.ravel(), yy.ravel(), z(xx, yy).ravel()])
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    v00 = (j * (nx + 1) + i).ravel()
    v10, v01, v11 = v00 + 1, v00 + nx + 1, v00 + nx + 2
    faces = np.vstack([np.column_stack([v00, v10, v11]), np.column_stack([v00, v11, v01])])
    return vertices, faces


def merge(*patches) -> NavMap:
    """One NavMap of the patches, vertices at the same place merged (shared edges connect)."""
    vertices, faces, offset = [], [], 0
    for v, f in patches:
        vertices.append(v)
        faces.append(f + offset)
        offset += len(v)
    vertices, faces = np.vstack(vertices), np.vstack(faces)
    _, first, inverse = np.unique(np.round(vertices, 6), axis=0, return_index=True,
                                  return_inverse=True)
    return NavMap(vertices[first], inverse.reshape(-1)[faces])


def two_floors() -> NavMap:
    """Ground floor (z 0) x 0..10, y 0..2 with a landing x 9..10, y 2..3; a ramp x 5..9,
    y 2..3 from z 0 at x 9 to 1.5 at x 5 (20.6 deg); an upper floor (z 1.5) x 0..5, y 0..3
    right above the ground floor's x 0..5."""
    return merge(
        patch(0, 10, 0, 2),
        patch(9, 10, 2, 3),
        patch(5, 9, 2, 3, lambda x, y: 1.5 * (9 - x) / 4 + 0 * y),
        patch(0, 5, 0, 3, lambda x, y: 1.5 + 0 * x),
    )


def steep_and_gentle() -> NavMap:
    """Ground (z 0) x 0..2, y 0..7 and an upper floor (z 1) x 3..5, y 0..7, joined by a steep
    ramp x 2..3, y 0..1 (45 deg) and by a gentle detour: a landing x 2..3, y 6..7 (z 0), a ramp
    x 2..3, y 2..6 (z 1 at y 2, 0 at y 6: 14 deg), a landing x 2..3, y 1..2 (z 1)."""
    return merge(
        patch(0, 2, 0, 7),
        patch(3, 5, 0, 7, lambda x, y: 1.0 + 0 * x),
        patch(2, 3, 0, 1, lambda x, y: x - 2.0 + 0 * y),
        patch(2, 3, 6, 7),
        patch(2, 3, 2, 6, lambda x, y: (6.0 - y) / 4.0 + 0 * x),
        patch(2, 3, 1, 2, lambda x, y: 1.0 + 0 * x),
    )


def random_mesh(rng, n=24) -> NavMap:
    """A jittered heightfield grid of n x n quads, random diagonals."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=float), np.arange(n + 1, dtype=float))
    xy = np.column_stack([xs.ravel(), ys.ravel()]) * 0.2
    xy += rng.uniform(-0.06, 0.06, xy.shape)
    z = rng.uniform(0.0, 0.3, len(xy))
    vertices = np.column_stack([xy, z])
    j, i = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    v00 = (j * (n + 1) + i).ravel()
    v10, v01, v11 = v00 + 1, v00 + n + 1, v00 + n + 2
    flip = rng.random(len(v00)) < 0.5
    a = np.where(flip, np.column_stack([v00, v10, v01]).T, np.column_stack([v00, v10, v11]).T).T
    b = np.where(flip, np.column_stack([v10, v11, v01]).T, np.column_stack([v00, v11, v01]).T).T
    return NavMap(vertices, np.vstack([a, b]))


def dijkstra_cost(navmap: NavMap, mult: np.ndarray, start: int, goal: int) -> float:
    """Cheapest cost by a plain Dijkstra (heapq, written here, independent of the planner's
    A*) over the NavCel graph with the planner's weights. scipy's csgraph gives the same in
    the benchmark; the test does without it, as easynav-planners installs without scipy."""
    u, v = navmap.adjacency_pairs()
    keep = np.isfinite(mult[v])
    u, v = u[keep], v[keep]
    w = np.linalg.norm(navmap.centroids[u] - navmap.centroids[v], axis=1) * mult[v]
    edges: dict[int, list[tuple[int, float]]] = {}
    for a, b, weight in zip(u.tolist(), v.tolist(), w.tolist(), strict=True):
        edges.setdefault(a, []).append((b, weight))
    best = {start: 0.0}
    queue = [(0.0, start)]
    while queue:
        cost, cell = heapq.heappop(queue)
        if cell == goal:
            return cost
        if cost > best.get(cell, math.inf):
            continue
        for nxt, weight in edges.get(cell, ()):
            if cost + weight < best.get(nxt, math.inf):
                best[nxt] = cost + weight
                heapq.heappush(queue, (cost + weight, nxt))
    return math.inf


# -- planner harness --------------------------------------------------------------------------
def make_planner(params=None) -> NavMapAStarPlanner:
    context = PluginContext(
        parameters=DictParameters({f"navmap.{k}": v for k, v in (params or {}).items()}),
        namespace=f"navmap_planner_test_{next(_namespaces)}",
        now=lambda: 7.0,
    )
    planner = NavMapAStarPlanner()
    planner.initialize(context, "navmap")
    return planner


def state_with(navmap, goal, robot=(0.5, 0.5, 0.0)) -> NavState:
    """``goal`` and ``robot`` are (x, y, z[, yaw])."""
    nav_state = NavState()
    nav_state.set("map.navmap", navmap)
    nav_state.set("robot_pose", Odometry(Header(3.0, "map"), "base_footprint",
                                         Pose.from_xy_yaw(robot[0], robot[1], 0.0, robot[2])))
    yaw = goal[3] if len(goal) > 3 else 0.0
    g = PoseStamped(Header(5.0, "map"), Pose.from_xy_yaw(goal[0], goal[1], yaw, goal[2]))
    nav_state.set("goals", Goals(Header(5.0, "map"), [g]))
    return nav_state


def plan(navmap, goal, robot=(0.5, 0.5, 0.0), params=None):
    planner = make_planner(params)
    nav_state = state_with(navmap, goal, robot)
    planner.update(nav_state)
    return planner, nav_state, nav_state.get("path", Path)


def points(path: Path) -> np.ndarray:
    return np.array([[p.x, p.y, p.z] for p in path.poses])


def diagnostic(nav_state) -> DiagnosticStatus:
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.hardware_id == "planner"
    return status


def planner_cells(planner):
    """The NavCels of the planner's last search."""
    return planner._last_cells


# -- optimal costs --------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(6))
def test_astar_cost_equals_dijkstra_on_random_meshes(seed):
    rng = np.random.default_rng(seed)
    navmap = random_mesh(rng)
    costs = rng.choice([0, 0, 0, 50, 120, 200, 253, 254, 255], navmap.num_navcels).astype(np.uint8)
    mult = step_multipliers(costs, navmap.num_navcels, rng.uniform(0.5, 3.0), rng.uniform(0, 8))
    free = np.flatnonzero(np.isfinite(mult))
    for _ in range(5):
        s, g = (int(c) for c in rng.choice(free, 2, replace=False))
        expected = dijkstra_cost(navmap, mult, s, g)
        ref_path, ref_cost = astar_navmap_reference(navmap.neighbors, navmap.centroids, mult,
                                                    s, g)
        fast_path, fast_cost = astar_navmap(navmap.neighbors, navmap.centroids, mult, s, g)
        if math.isinf(expected):
            assert ref_path is None and fast_path is None
            continue
        assert ref_cost == pytest.approx(expected, rel=1e-9)
        assert fast_cost == pytest.approx(expected, rel=1e-9)
        for cells in (ref_path, fast_path):
            cells = np.asarray(cells)
            assert cells[0] == s and cells[-1] == g
            assert all(b in navmap.neighbors[a] for a, b in zip(cells[:-1], cells[1:],
                                                                  strict=True))
            assert path_cost(navmap.centroids, mult, cells) == pytest.approx(expected, rel=1e-9)


def test_compiled_search_is_available():
    pytest.importorskip("numba")  # the numba extra (installed by the repository's set-up)
    assert compiled_available()


def test_two_floors_path_climbs_the_ramp_and_costs_what_dijkstra_says():
    navmap = two_floors()
    # The ground floor's (1, 1) and the upper floor's (1, 1) are 1.5 m apart vertically.
    planner, nav_state, path = plan(navmap, (1.0, 1.0, 1.5, 0.7), robot=(1.0, 1.0, 0.0))
    pts = points(path)
    assert pts[0] == pytest.approx([1.0, 1.0, 0.0])
    assert pts[-1] == pytest.approx([1.0, 1.0, 1.5])
    assert path.poses[-1].yaw == pytest.approx(0.7)
    # Out along the ground floor, up the ramp (x 9 -> 5 at y 2..3), back on the upper floor.
    assert pts[:, 0].max() > 8.9 and (pts[:, 2] > 0.1).any()
    on_ramp = (pts[:, 0] > 5.2) & (pts[:, 0] < 8.8) & (pts[:, 2] > 0.05)
    assert (pts[on_ramp, 1] > 2.0).all()
    np.testing.assert_allclose(pts[on_ramp, 2], 1.5 * (9 - pts[on_ramp, 0]) / 4, atol=1e-9)
    cells = planner_cells(planner)
    mult = step_multipliers(None, navmap.num_navcels, 2.0, 5.0)
    expected = dijkstra_cost(navmap, mult, int(cells[0]), int(cells[-1]))
    assert path_cost(navmap.centroids, mult, cells) == pytest.approx(expected, rel=1e-9)
    ref, _ = astar_navmap_reference(navmap.neighbors, navmap.centroids, mult, int(cells[0]),
                                    int(cells[-1]))
    assert ref[0] == cells[0]
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.OK and "path of" in status.message
    # The same xy goal at z 0 is the ground floor: a short straight path.
    _, _, low = plan(navmap, (1.0, 1.8, 0.0), robot=(1.0, 1.0, 0.0))
    assert (points(low)[:, 2] == 0.0).all() and len(low) < 25


# -- slopes --------------------------------------------------------------------------
def test_slope_limit_takes_the_gentle_detour_no_limit_the_steep_ramp():
    navmap = steep_and_gentle()
    goal, robot = (4.0, 0.5, 1.0), (1.0, 0.5, 0.0)
    _, _, steep = plan(navmap, goal, robot)
    assert (points(steep)[:, 1] < 1.2).all()  # straight up the 45 deg ramp
    _, nav_state, gentle = plan(navmap, goal, robot, {"max_allowed_slope_deg": 30.0})
    pts = points(gentle)
    assert pts[:, 1].max() > 6.0  # round by the far landing and the 14 deg ramp
    assert pts[-1] == pytest.approx([4.0, 0.5, 1.0])
    # Nothing steeper than the limit is entered.
    cells, _ = navmap.locate(pts)
    slopes = np.degrees(np.arccos(np.abs(navmap.normals[cells, 2])))
    assert slopes.max() < 30.0
    assert diagnostic(nav_state).level == DiagnosticLevel.OK


def test_no_route_within_the_slope_limit_and_a_goal_on_a_steep_navcel():
    navmap = steep_and_gentle()
    planner, nav_state, path = plan(navmap, (4.0, 0.5, 1.0), (1.0, 0.5, 0.0),
                                    {"max_allowed_slope_deg": 10.0})
    assert len(path) == 0
    assert "slopes above 10 deg" in diagnostic(nav_state).message
    assert planner.take_goal_rejection() is None
    planner, nav_state, path = plan(navmap, (2.5, 0.5, 0.5), (1.0, 0.5, 0.0),
                                    {"max_allowed_slope_deg": 30.0})
    assert len(path) == 0
    assert "sloped 45.0 deg" in diagnostic(nav_state).message
    assert "sloped 45.0 deg" in planner.take_goal_rejection()


# -- costs --------------------------------------------------------------------------
@pytest.mark.parametrize("layer", ["obstacles", "inflated_obstacles"])
@pytest.mark.parametrize(("value", "words"), [(254, "on an obstacle (cost 254)"),
                                              (255, "on unknown space (cost 255)")])
def test_goal_or_start_on_lethal_or_unknown_gives_an_empty_path_and_says_why(layer, value,
                                                                              words):
    navmap = merge(patch(0, 6, 0, 3))
    goal_cid = navmap.locate_navcel((5.0, 1.5, 0.0))
    navmap.add_layer(layer)[goal_cid] = value
    planner, nav_state, path = plan(navmap, (5.0, 1.5, 0.0))
    assert len(path) == 0
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.WARN
    assert status.message == f"goal (5.00, 1.50) is {words} in NavMap layer '{layer}'"
    assert planner.take_goal_rejection() is None  # may clear: the recovery system decides
    # The robot on it.
    _, nav_state, path = plan(navmap, (1.0, 1.0, 0.0), robot=(5.0, 1.5, 0.0))
    assert len(path) == 0
    assert f"the robot (5.00, 1.50, 0.00) is {words}" in diagnostic(nav_state).message


def test_a_goal_off_the_mesh_is_rejected():
    navmap = merge(patch(0, 6, 0, 3))
    planner, nav_state, path = plan(navmap, (8.0, 1.0, 0.0))
    assert len(path) == 0
    assert "is not on the NavMap" in planner.take_goal_rejection()


def test_layer_costs_push_the_path_away():
    navmap = merge(patch(0, 6, 0, 4))
    c = navmap.centroids
    band = (np.abs(c[:, 0] - 3.0) < 0.5) & (c[:, 1] < 3.0)
    navmap.add_layer("inflated_obstacles")[band] = 250
    navmap.add_layer("obstacles")  # all free: the inflated layer wins
    goal, robot = (5.5, 1.5, 0.0), (0.5, 1.5, 0.0)
    _, _, around = plan(navmap, goal, robot)
    pts = points(around)
    middle = np.abs(pts[:, 0] - 3.0) < 0.4
    assert middle.any() and (pts[middle, 1] > 3.0).all()
    # Without the penalty the costs do not matter: straight through.
    _, _, straight = plan(navmap, goal, robot, {"inflation_penalty": 0.0})
    assert np.abs(points(straight)[:, 1] - 1.5).max() < 0.2


def test_a_blocked_route_gives_an_empty_path():
    navmap = merge(patch(0, 6, 0, 3))
    navmap.add_layer("obstacles")[np.abs(navmap.centroids[:, 0] - 3.0) < 0.1] = 254
    planner, nav_state, path = plan(navmap, (5.0, 1.5, 0.0))
    assert len(path) == 0
    assert "no route from (0.50, 0.50, 0.00) to goal (5.00, 1.50): blocked by layer " \
           "'obstacles'" == diagnostic(nav_state).message
    assert planner.take_goal_rejection() is None


# -- smoothing and poses -----------------------------------------------------------------------
def test_smoothing_keeps_the_ends_and_every_point_on_its_triangle():
    navmap = two_floors()
    start, goal = navmap.locate_navcel((1.0, 1.0, 0.0)), navmap.locate_navcel((1.0, 1.0, 1.5))
    mult = step_multipliers(None, navmap.num_navcels)
    cells, _ = astar_navmap(navmap.neighbors, navmap.centroids, mult, start, goal)
    raw = navmap.centroids[cells]
    smooth = smooth_on_navcels(raw, cells, navmap)
    assert smooth[0] == pytest.approx(raw[0]) and smooth[-1] == pytest.approx(raw[-1])
    assert not np.allclose(smooth, raw)
    length = np.linalg.norm(np.diff(smooth, axis=0), axis=1).sum()
    assert length < np.linalg.norm(np.diff(raw, axis=0), axis=1).sum()
    # Each point inside its own NavCel's xy triangle, z on its plane.
    tri = navmap.vertices[navmap.faces[cells]]
    again = clamp_to_triangles(smooth[:, :2], tri)
    np.testing.assert_allclose(again, smooth, atol=1e-9)
    heights = navmap.locate(smooth)[1]
    np.testing.assert_allclose(heights, smooth[:, 2], atol=1e-9)


def test_clamp_to_triangles_projects_outside_points_to_the_nearest_edge():
    tri = np.array([[[0, 0, 0], [1, 0, 1], [0, 1, 2]]], dtype=float)
    assert clamp_to_triangles([[0.25, 0.25]], tri)[0] == pytest.approx([0.25, 0.25, 0.75])
    assert clamp_to_triangles([[2.0, -1.0]], tri)[0] == pytest.approx([1.0, 0.0, 1.0])
    assert clamp_to_triangles([[1.0, 1.0]], tri)[0] == pytest.approx([0.5, 0.5, 1.5])


def test_poses_face_the_next_and_the_last_takes_the_goal_yaw():
    navmap = merge(patch(0, 6, 0, 3))
    _, _, path = plan(navmap, (5.0, 2.5, 0.0, -1.0))
    pts = points(path)
    d = np.diff(pts, axis=0)
    np.testing.assert_allclose([p.yaw for p in path.poses[:-1]], np.arctan2(d[:, 1], d[:, 0]))
    assert path.poses[-1].yaw == pytest.approx(-1.0)
    assert path.header.frame_id == "map" and path.header.stamp == 7.0
    # On the goal's NavCel already: the goal alone.
    goal_cid = navmap.locate_navcel((5.0, 2.5, 0.0))
    inside = navmap.centroids[goal_cid]
    _, _, one = plan(navmap, (5.0, 2.5, 0.0, -1.0), robot=(inside[0], inside[1], 0.0))
    np.testing.assert_allclose(points(one), [[5.0, 2.5, 0.0]])


def test_continuous_replan_false_keeps_the_path_until_it_is_blocked():
    navmap = merge(patch(0, 6, 0, 3))
    planner = make_planner({"continuous_replan": False})
    nav_state = state_with(navmap, (5.0, 1.5, 0.0))
    planner.update(nav_state)
    first = nav_state.get("path", Path)
    nav_state.set("robot_pose", Odometry(Header(3.0, "map"), "base_footprint",
                                         Pose.from_xy_yaw(1.0, 1.0, 0.0)))
    planner.update(nav_state)
    assert nav_state.get("path", Path) is first
    blocked = navmap.copy()
    cells, _ = blocked.locate(points(first)[len(first) // 2][None, :])
    blocked.add_layer("obstacles")[cells] = 254
    nav_state.set("map.navmap", blocked)
    planner.update(nav_state)
    second = nav_state.get("path", Path)
    assert second is not first and len(second) > 0
    assert points(second)[0] == pytest.approx([1.0, 1.0, 0.0])


def test_robot_just_off_the_mesh_starts_from_the_nearest_navcel_far_off_fails():
    navmap = merge(patch(0, 6, 0, 3))
    _, _, path = plan(navmap, (5.0, 1.5, 0.0), robot=(-0.1, 1.0, 0.0))
    assert len(path) > 0
    _, nav_state, path = plan(navmap, (5.0, 1.5, 0.0), robot=(-3.0, 1.0, 0.0))
    assert len(path) == 0 and "is off the NavMap" in diagnostic(nav_state).message


def test_no_navmap_yet():
    planner = make_planner()
    nav_state = NavState()
    nav_state.set("robot_pose", Odometry(Header(3.0, "map"), "base_footprint", Pose()))
    nav_state.set("goals", Goals(Header(5.0, "map"), [PoseStamped(Header(5.0, "map"),
                                                                   Pose.from_xy_yaw(1, 1))]))
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert "no NavMap yet" in diagnostic(nav_state).message


# -- straightening (smooth_path) ------------------------------------------------------------
def walk_cost_of(navmap, mult, xy, cells) -> float:
    """The cost of a straightened path under the planner's model, recomputed here: each
    segment's length inside each NavCel (found by sampling the segment densely and locating
    the samples) times that NavCel's multiplier."""
    total = 0.0
    for a, b in zip(xy[:-1], xy[1:], strict=True):
        n = max(2, int(np.hypot(*(b - a)) / 0.002))
        ts = (np.arange(n) + 0.5) / n
        samples = a[None, :] + ts[:, None] * (b - a)[None, :]
        cids, _ = navmap.locate(np.column_stack([samples, np.zeros(n)]))
        assert (cids >= 0).all(), "a straightened segment leaves the mesh"
        total += float((mult[cids] * np.hypot(*(b - a)) / n).sum())
    return total


def test_walk_segment_follows_the_line_and_refuses_what_it_must():
    navmap = merge(patch(0, 2, 0, 1))
    xy, faces, nbrs = navmap.vertices[:, :2], navmap.faces, navmap.neighbors
    mult = step_multipliers(None, navmap.num_navcels, 2.0, 5.0)
    p, q = np.array([0.13, 0.07]), np.array([1.71, 0.88])
    cids, _ = navmap.locate(np.array([[*p, 0.0], [*q, 0.0]]))
    walked = walk_segment(xy, faces, nbrs, mult, int(cids[0]), int(cids[1]), p, q)
    assert walked is not None
    crossed, entries, cost = walked
    assert crossed[-1] == cids[1]
    assert cost == pytest.approx(2.0 * np.hypot(*(q - p)), rel=1e-12)
    steps = [int(cids[0]), *crossed]
    assert all(b in navmap.neighbors[a] for a, b in zip(steps[:-1], steps[1:], strict=True))
    for e in entries:  # every crossing lies on the line
        assert abs((q - p)[0] * (e[1] - p[1]) - (q - p)[1] * (e[0] - p[0])) < 1e-12
    blocked = mult.copy()
    blocked[crossed[len(crossed) // 2]] = np.inf
    assert walk_segment(xy, faces, nbrs, blocked, int(cids[0]), int(cids[1]), p, q) is None
    # Through vertices, across the grid's other diagonal (every grid point on x + y = 1):
    # walked as if just right of them, the NavCels round each vertex on that side included.
    a, b = np.array([0.1 + 0.2 / 3, 0.9 - 0.2 / 3]), np.array([0.9 - 0.1 / 3, 0.1 + 0.1 / 3])
    ends, _ = navmap.locate(np.array([[*a, 0.0], [*b, 0.0]]))
    walked = walk_segment(xy, faces, nbrs, mult, int(ends[0]), int(ends[1]), a, b)
    assert walked is not None
    crossed, entries, cost = walked
    assert cost == pytest.approx(2.0 * np.hypot(*(b - a)), rel=1e-12)
    steps = [int(ends[0]), *crossed]
    assert all(n in navmap.neighbors[m] for m, n in zip(steps[:-1], steps[1:], strict=True))
    right = navmap.centroids[crossed][:, :2] - a
    assert ((b - a)[0] * right[:, 1] - (b - a)[1] * right[:, 0] <= 1e-12).all()
    vertex = walked[1][len(walked[1]) // 2]
    vertex_blocked = mult.copy()  # a NavCel right of a vertex on the line, on the way
    vertex_blocked[crossed[len(crossed) // 2]] = np.inf
    assert walk_segment(xy, faces, nbrs, vertex_blocked, int(ends[0]), int(ends[1]), a, b) is None
    assert vertex is not None
    # Off the mesh and back: refused.
    holed = merge(patch(0, 1, 0, 1), patch(1, 2, 0, 0.5), patch(1, 2, 0.5, 1), patch(2, 3, 0, 1))
    keep = holed.centroids[:, 0] < 1.0
    keep |= holed.centroids[:, 0] > 2.0
    keep |= holed.centroids[:, 1] < 0.5
    cut = NavMap(holed.vertices, holed.faces[keep])
    a, b = np.array([0.5, 0.9]), np.array([2.5, 0.9])
    ends, _ = cut.locate(np.array([[*a, 0.0], [*b, 0.0]]))
    free = step_multipliers(None, cut.num_navcels, 2.0, 5.0)
    assert walk_segment(cut.vertices[:, :2], cut.faces, cut.neighbors, free, int(ends[0]),
                        int(ends[1]), a, b) is None


def test_straightened_path_across_the_grid_diagonal_is_the_straight_line():
    """On a grid mesh split along one diagonal, A* across the other diagonal returns a
    staircase of right-angle turns (the original's path); straightened, it is the line."""
    navmap = merge(patch(0, 4, 0, 4))
    start, goal = (3.53, 0.47, 0.0), (0.47, 3.53, 0.0, 2.0)
    _, _, original = plan(navmap, goal, robot=start, params={"smooth_path": False})
    _, _, straight = plan(navmap, goal, robot=start)
    for path in (original, straight):
        pts = points(path)
        assert pts[0] == pytest.approx(start) and pts[-1] == pytest.approx(goal[:3])
    length = math.hypot(3.06, 3.06)
    turns = np.abs(np.diff(np.unwrap([p.yaw for p in original.poses[:-1]])))
    assert (turns > math.radians(10)).sum() >= 30  # the staircase, smoothed a little
    wiggly = np.linalg.norm(np.diff(points(original)[:, :2], axis=0), axis=1).sum()
    assert wiggly > 1.2 * length
    pts = points(straight)
    d = np.diff(pts[:, :2], axis=0)
    assert np.linalg.norm(d, axis=1).sum() == pytest.approx(length, rel=1e-9)
    assert np.allclose([p.yaw for p in straight.poses[:-1]], math.atan2(3.06, -3.06))
    assert straight.poses[-1].yaw == pytest.approx(2.0)


@pytest.mark.parametrize("seed", range(6))
def test_straightened_path_is_never_costlier_and_stays_on_enterable_navcels(seed):
    rng = np.random.default_rng(100 + seed)
    navmap = random_mesh(rng)
    costs = rng.choice([0, 0, 0, 0, 50, 120, 200, 253, 254], navmap.num_navcels).astype(np.uint8)
    mult = step_multipliers(costs, navmap.num_navcels, 2.0, 5.0)
    free = np.flatnonzero(np.isfinite(mult))
    for _ in range(5):
        s, g = (int(c) for c in rng.choice(free, 2, replace=False))
        cells, _ = astar_navmap_reference(navmap.neighbors, navmap.centroids, mult, s, g)
        if cells is None:
            continue
        pts = navmap.centroids[cells]
        xy, crossed = shortcut_path(pts, cells, navmap.vertices[:, :2], navmap.faces,
                                    navmap.neighbors, mult)
        assert xy[0] == pytest.approx(pts[0, :2]) and xy[-1] == pytest.approx(pts[-1, :2])
        assert crossed[0] == s and crossed[-1] == g
        assert np.isfinite(mult[crossed]).all()
        assert all(b in navmap.neighbors[a] or a == b
                   for a, b in zip(crossed[:-1], crossed[1:], strict=True))
        # Both costs as lines over the flattened mesh (the multiplier of the NavCel under
        # each point, integrated along the polyline): the straightened path's is no more.
        flat = NavMap(np.column_stack([navmap.vertices[:, :2], np.zeros(len(navmap.vertices))]),
                      navmap.faces)
        before = walk_cost_of(flat, mult, pts[:, :2], cells)
        assert walk_cost_of(flat, mult, xy, crossed) <= before * (1 + 1e-3) + 1e-6


def test_straightened_path_never_cuts_into_costlier_navcels_than_its_stretch():
    """The band of inflated NavCels the path goes round (test_layer_costs_push_the_path_away):
    the straightened path goes round it as well, on free NavCels only (a line across the
    band's corner would be shorter, and under the cost model even cheaper than A*'s
    staircase), with straight stretches instead of the staircase."""
    navmap = merge(patch(0, 6, 0, 4))
    c = navmap.centroids
    band = (np.abs(c[:, 0] - 3.0) < 0.5) & (c[:, 1] < 3.0)
    navmap.add_layer("inflated_obstacles")[band] = 250
    goal, robot = (5.5, 1.5, 0.0), (0.5, 1.5, 0.0)
    planner, _, path = plan(navmap, goal, robot)
    assert not band[planner._last_crossed].any()
    pts = points(path)
    middle = np.abs(pts[:, 0] - 3.0) < 0.4
    assert middle.any() and (pts[middle, 1] > 3.0).all()
    _, _, original = plan(navmap, goal, robot, {"smooth_path": False})
    for p in (path, original):
        assert not band[navmap.locate(points(p))[0]].any()
    turns = [np.abs(np.diff(np.unwrap([p.yaw for p in q.poses[:-1]]))) for q in (path, original)]
    assert (turns[0] > math.radians(10)).sum() < (turns[1] > math.radians(10)).sum() / 4


@pytest.mark.parametrize("seed", range(6))
def test_compiled_straightening_gives_the_reference_answer(seed):
    pytest.importorskip("numba")  # the numba extra (installed by the repository's set-up)
    from easynav.planners import navmap_shortcut

    assert navmap_shortcut._KERNEL.available()
    rng = np.random.default_rng(200 + seed)
    navmap = random_mesh(rng, n=30)
    costs = rng.choice([0, 0, 0, 0, 0, 50, 120, 253, 254], navmap.num_navcels).astype(np.uint8)
    mult = step_multipliers(costs, navmap.num_navcels, 2.0, 5.0)
    free = np.flatnonzero(np.isfinite(mult))
    compared = 0
    for _ in range(8):
        s, g = (int(c) for c in rng.choice(free, 2, replace=False))
        cells, _ = astar_navmap_reference(navmap.neighbors, navmap.centroids, mult, s, g)
        if cells is None or len(cells) < 3:
            continue
        args = (navmap.centroids[cells], np.asarray(cells), navmap.vertices, navmap.faces,
                navmap.neighbors, mult)
        ref_xy, ref_cells = navmap_shortcut.shortcut_path_reference(*args)
        fast_xy, fast_cells = navmap_shortcut.shortcut_path(*args)
        np.testing.assert_array_equal(fast_cells, ref_cells)
        np.testing.assert_allclose(fast_xy, ref_xy, rtol=0, atol=1e-12)
        compared += 1
    assert compared >= 3


def test_kept_straightened_path_knows_every_navcel_it_crosses():
    """continuous_replan false keeps the path while none of its NavCels is blocked: every
    NavCel the straightened path runs through counts, also those whose crossing points were
    left out for being within a centimetre of another (at each vertex of a grid's diagonal)."""
    navmap = merge(patch(0, 4, 0, 4))
    navmap.add_layer("obstacles")
    robot, goal = (3.53, 0.47, 0.0), (0.47, 3.53, 0.0, 2.0)
    planner = make_planner({"continuous_replan": False})
    nav_state = state_with(navmap, goal, robot)
    planner.update(nav_state)
    pts = points(nav_state.get("path", Path))
    ts = (np.arange(50) + 0.5)[:, None] / 50  # inside each segment, off its ends (vertices)
    samples = np.concatenate([a + ts * (b - a) for a, b in zip(pts[:-1], pts[1:], strict=True)])
    under, _ = navmap.locate(samples)
    assert set(under.tolist()) <= set(planner._last_crossed.tolist())
    # Block a NavCel the path runs through but holds no point of: the path is planned again.
    pointless = sorted(set(under.tolist()) - set(navmap.locate(pts)[0].tolist()))
    assert pointless
    navmap.layer("obstacles")[pointless[len(pointless) // 2]] = 254
    planner.update(nav_state)
    assert "path kept" not in diagnostic(nav_state).message
    replanned = points(nav_state.get("path", Path))
    assert pointless[len(pointless) // 2] not in navmap.locate(replanned)[0]


@pytest.mark.parametrize("compiled", [True, False])
def test_straightening_from_a_navcel_steeper_than_the_limit(compiled, monkeypatch):
    """The robot on a NavCel steeper than max_allowed_slope_deg (its multiplier infinite: A*
    never enters it, but starts from it): the path still keeps off the band of inflated
    NavCels it goes round, compiled or not."""
    from easynav.planners import navmap_shortcut

    if compiled:
        pytest.importorskip("numba")
    else:
        monkeypatch.setattr(navmap_shortcut._KERNEL, "_kernel", False)

    def bump(x, y):
        return np.where((np.abs(x - 0.2) < 1e-9) & (np.abs(y - 0.2) < 1e-9), 0.3, 0.0)

    navmap = merge(patch(0, 3, 0, 1, bump))
    c = navmap.centroids
    band = (np.abs(c[:, 0] - 1.5) < 0.3) & (c[:, 1] < 0.8)
    layer = navmap.add_layer("inflated_obstacles")
    layer[band] = 253
    robot, goal = (0.23, 0.21, 0.05), (2.77, 0.21, 0.0, 0.0)
    planner, nav_state, path = plan(navmap, goal, robot, {"max_allowed_slope_deg": 45.0})
    assert not math.isfinite(step_multipliers(layer, navmap.num_navcels, 2.0, 5.0, planner._steep(
        navmap))[planner._last_cells[0]])
    assert not band[planner._last_crossed].any()
    assert len(path) > 2 and points(path)[:, 1].max() > 0.8


def test_straightened_path_to_a_goal_on_a_vertex_ends_with_a_real_segment():
    """A goal on a grid vertex (round coordinates): the line reaches it through the NavCels
    round the vertex, whose entry points are the goal itself; none is left before the goal, so
    the last pose but one faces the goal."""
    navmap = merge(patch(0, 4, 0, 4))
    for gx, gy in itertools.product((0.5, 1.1, 1.7, 2.3, 2.9, 3.5), (0.5, 1.2, 1.9, 2.6, 3.3)):
        _, _, path = plan(navmap, (gx, gy, 0.0, 0.0), (0.23, 0.37, 0.0))
        pts = points(path)
        last = pts[-1, :2] - pts[-2, :2]
        assert np.hypot(*last) >= 0.01, (gx, gy)
        assert path.poses[-2].yaw == pytest.approx(math.atan2(last[1], last[0]), abs=1e-9)


def test_straightened_path_from_inside_the_inflation_leaves_it_as_a_star_does():
    """A robot against the corner of a block, inside its inflation (as after a collision):
    the path leaves the inflation the way A* does before any shortcut, and once on free
    NavCels it stays on them; a line from the robot, allowed the robot's own cost all along,
    ran past the corner inside the inflation and kept the robot against it."""
    navmap = merge(patch(0, 6, 0, 6))
    c = navmap.centroids
    block = (c[:, 0] > 3.0) & (c[:, 0] < 5.0) & (c[:, 1] > 1.0) & (c[:, 1] < 4.0)
    d = np.hypot(np.clip(c[:, 0], 3.0, 5.0) - c[:, 0], np.clip(c[:, 1], 1.0, 4.0) - c[:, 1])
    costs = np.where(block, 254, np.where(d <= 0.3, 253, np.where(
        d <= 0.6, 253 * np.exp(-5 * (d - 0.3)), 0))).astype(np.uint8)
    navmap.set_layer("inflated_obstacles", costs, np.uint8)
    robot = (3.1, 4.28, 0.0)  # against the block's north face, by its north-west corner
    goal = (1.0, 1.5, 0.0, 0.0)  # the straight line passes 0.1 m from that corner
    planner, _, path = plan(navmap, goal, robot)
    crossed = planner._last_crossed
    free = np.flatnonzero(costs[crossed] == 0)
    assert len(free) and (costs[crossed[free[0]:]] == 0).all()
    # No nearer the corner than A*'s own path (the line from the robot passed 0.1 m from it).
    pts = points(path)
    star = navmap.centroids[planner._last_cells]
    assert np.hypot(pts[:, 0] - 3.0, pts[:, 1] - 4.0).min() >= np.hypot(
        star[:, 0] - 3.0, star[:, 1] - 4.0).min() - 0.05
    assert np.hypot(pts[:, 0] - 3.0, pts[:, 1] - 4.0).min() > 0.2
