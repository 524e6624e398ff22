"""OMPLGridPlanner and FootprintChecker without ROS: every path checked by direct computation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.core.types import Costmap2D

pytest.importorskip("ompl", reason="the OMPL planner needs the [ompl] extra")

from easynav.planners.footprint_checker import FootprintChecker  # noqa: E402
from easynav.planners.ompl_grid_planner import (  # noqa: E402
    ANYTIME_PLANNERS,
    PLANNERS,
    THREADED_PLANNERS,
    OMPLGridPlanner,
)

#: A budget no plan expected to succeed needs, even on a loaded machine (the planners used stop
#: at their first solution or at max_iterations).
LONG = 60.0


def bounded(planner: str) -> dict:
    """A budget bounded by work, not the clock, where OMPL allows it: the same result however
    loaded the machine is. First-solution planners stop by themselves (LONG budget); anytime
    ones after 800 iterations; PRM and PRM* (threaded: clock only) after 5 s, a hundred times
    what they need on an idle machine."""
    if planner in THREADED_PLANNERS:
        return {"solve_time": 5.0}
    if planner in ANYTIME_PLANNERS:
        return {"solve_time": LONG, "max_iterations": 800}
    return {"solve_time": LONG}


def make(*args, **kwargs) -> OMPLGridPlanner:
    """An OMPLGridPlanner with the LONG budget unless told otherwise."""
    kwargs.setdefault("solve_time", LONG)
    return OMPLGridPlanner(*args, **kwargs)


def wall_map() -> Costmap2D:
    """10 m x 10 m at 0.05 m, a wall x 4.75..5.25 from y = 0 to 8 (pass above it)."""
    costmap = Costmap2D.filled(200, 200, 0.05)
    costmap.data[0:160, 95:105] = 254
    return costmap


def clutter_map(seed: int = 4) -> Costmap2D:
    """8 m x 6 m with random boxes (lethal), inflation-like graded cells and unknown patches."""
    rng = np.random.default_rng(seed)
    costmap = Costmap2D.filled(160, 120, 0.05, origin_x=-1.0, origin_y=-2.0)
    for _ in range(14):
        x, y = rng.integers(10, 150), rng.integers(10, 110)
        w, h = rng.integers(3, 16), rng.integers(3, 16)
        costmap.data[y : y + h, x : x + w] = 254
    costmap.data[costmap.data == 0] = rng.integers(0, 200, int((costmap.data == 0).sum()))
    costmap.data[0:4, 0:20] = 255
    # Keep the start and goal areas clear.
    costmap.data[8:30, 4:26] = 0
    costmap.data[90:112, 134:156] = 0
    return costmap


def obstacle_centres(costmap: Costmap2D) -> np.ndarray:
    iy, ix = np.nonzero(costmap.data >= 254)
    return np.stack(costmap.cell_to_world(ix, iy), axis=1)


def assert_clear(costmap: Costmap2D, poses: np.ndarray, radius: float) -> None:
    """Every point of the polyline (sampled at a quarter cell) is on the map and farther than
    ``radius`` from every obstacle cell centre: brute force, independent of FootprintChecker."""
    xy = poses[:, :2]
    step = 0.25 * costmap.resolution
    samples = [xy[:1]]
    for a, b in zip(xy[:-1], xy[1:], strict=True):
        n = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
        samples.append(a + (np.arange(1, n + 1)[:, None] / n) * (b - a))
    points = np.concatenate(samples)
    x0, y0, x1, y1 = costmap.extent()
    assert (points[:, 0] >= x0).all() and (points[:, 0] < x1).all()
    assert (points[:, 1] >= y0).all() and (points[:, 1] < y1).all()
    centres = obstacle_centres(costmap)
    for chunk in np.array_split(points, max(1, len(points) // 500)):
        d = np.hypot(chunk[:, None, 0] - centres[None, :, 0],
                     chunk[:, None, 1] - centres[None, :, 1])
        assert d.min() > radius, f"a path point is {d.min():.3f} m from an obstacle"


# -- FootprintChecker -------------------------------------------------------------------------


def test_free_positions_have_no_obstacle_centre_within_the_radius():
    costmap = clutter_map()
    checker = FootprintChecker(costmap, 0.35)
    centres = obstacle_centres(costmap)
    rng = np.random.default_rng(1)
    x0, y0, x1, y1 = costmap.extent()
    points = np.stack([rng.uniform(x0, x1, 4000), rng.uniform(y0, y1, 4000)], axis=1)
    free = checker.are_free(points)
    assert free.any() and (~free).any()
    d = np.hypot(points[:, None, 0] - centres[None, :, 0], points[:, None, 1] - centres[None, :, 1])
    assert (d[free].min(axis=1) > 0.35).all()
    # Conservative by at most a cell: points well clear of everything are free.
    edge = np.minimum.reduce([points[:, 0] - x0, x1 - points[:, 0], points[:, 1] - y0,
                              y1 - points[:, 1]])
    clear = (d.min(axis=1) > 0.35 + 2 * costmap.resolution) & (edge > 0.35 + 0.1)
    assert free[clear].all()
    # The scalar test agrees with the vectorised one.
    assert [checker.is_free(*p) for p in points[:300]] == free[:300].tolist()


def test_off_the_map_and_nan_are_not_free_and_unknown_is_an_obstacle_unless_allowed():
    costmap = Costmap2D.filled(40, 40, 0.1)
    costmap.data[:, 30:] = 255
    checker = FootprintChecker(costmap, 0.2)
    assert checker.is_free(1.0, 2.0)
    assert not checker.is_free(-0.5, 2.0) and not checker.is_free(math.nan, 2.0)
    assert not checker.is_free(2.9, 2.0)
    assert FootprintChecker(costmap, 0.2, allow_unknown=True).is_free(3.5, 2.0)
    assert not checker.are_free(np.array([[math.nan, 1.0], [5.0, 1.0]])).any()


def test_with_radius_shares_the_map_and_bad_arguments_are_named():
    costmap = wall_map()
    checker = FootprintChecker(costmap, 0.3)
    wider = checker.with_radius(1.0)
    assert wider.clearance is checker.clearance
    assert checker.is_free(4.2, 4.0) and not wider.is_free(4.2, 4.0)
    with pytest.raises(ValueError, match="radius"):
        FootprintChecker(costmap, -1.0)
    with pytest.raises(ValueError, match="obstacle_cost"):
        FootprintChecker(costmap, 0.3, obstacle_cost=0)
    with pytest.raises(ValueError, match="empty"):
        FootprintChecker(Costmap2D(), 0.3)


def test_free_regions_join_what_a_moving_disc_can_join():
    costmap = Costmap2D.filled(100, 60, 0.05)  # 5 m x 3 m
    costmap.data[:, 48:52] = 254  # a wall across the map at x 2.4..2.6
    checker = FootprintChecker(costmap, 0.1)
    left, right = (1.0, 1.5), (4.0, 1.5)
    assert not checker.connected(left, right)
    assert checker.region_label(2.5, 1.5) == 0  # inside the wall: no region
    assert checker.region_extent(2.5, 1.5) is None
    costmap.data[20:26, 48:52] = 0  # a gap 0.3 m wide: the 0.2 m disc passes, a 0.4 m one not
    narrow = FootprintChecker(costmap, 0.1)
    assert narrow.connected(left, right)
    assert not narrow.with_radius(0.2).connected(left, right)
    # The box of a region: its free cells' extent (the radius in from the map edge, here cells
    # 2..97 and 2..57), a cell wider on every side.
    x0, y0, x1, y1 = FootprintChecker(Costmap2D.filled(100, 60, 0.05), 0.1).region_extent(*left)
    assert (x0, y0, x1, y1) == pytest.approx((0.05, 0.05, 4.95, 2.95))


def test_a_goal_on_the_edge_of_its_region_is_inside_the_bounds_ompl_samples():
    # The region's first column starts at -7.55 m, which the grid computes as
    # -7.549999999999999: a goal at -7.55 was outside OMPL's bounds ("Invalid goal").
    costmap = Costmap2D.filled(120, 60, 0.05, origin_x=-9.6, origin_y=-1.0)
    costmap.data[:, 0:36] = 254
    ompl = OMPLGridPlanner(solve_time=LONG, seed=1, robot_radius=0.1, clearance_distance=0.0)
    checker = ompl.planning_checker(costmap)
    goal = (-7.55, 0.5)
    assert checker.is_free(*goal)
    assert checker.region_extent(*goal)[0] < goal[0]
    result = ompl.plan(costmap, (-5.0, 0.5, 0.0), (*goal, 0.0))
    assert result.ok, result.reason


def test_polyline_check_finds_a_segment_through_a_wall():
    checker = FootprintChecker(wall_map(), 0.3)
    assert checker.polyline_free(np.array([[2.0, 2.0], [2.0, 5.0]])) == (True, -1)
    assert checker.polyline_free(np.array([[2.0, 5.0], [2.0, 2.0], [8.0, 2.0]])) == (False, 1)


# -- OMPLGridPlanner --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("space", "planner"),
    [("SE2", "RRTConnect"), ("SE2", "RRTstar"), ("SE2", "PRMstar"), ("SE2", "BITstar"),
     ("SE2", "KPIECE1"), ("Dubins", "RRTConnect"), ("Dubins", "InformedRRTstar"),
     ("ReedsShepp", "RRTConnect"), ("ReedsShepp", "BITstar")],
)
def test_every_returned_path_is_clear_of_obstacles(space, planner):
    costmap = clutter_map()
    # Bounded by iterations, not the clock: the same work however loaded the machine is (the
    # first-solution planners stop long before).
    ompl = OMPLGridPlanner(space, planner, **bounded(planner), seed=7, robot_radius=0.25,
                           clearance_distance=0.05, turning_radius=0.4)
    start, goal = (-0.2, -1.0, 0.0), (5.7, 3.0, 1.0)
    result = ompl.plan(costmap, start, goal)
    assert result.ok, result.reason
    assert result.poses[0, :2].tolist() == [-0.2, -1.0]
    assert result.poses[-1].tolist() == pytest.approx(list(goal))
    assert_clear(costmap, result.poses, 0.30)
    spacing = np.hypot(*np.diff(result.poses[:, :2], axis=0).T)
    assert spacing.max() <= 0.1 + 1e-6  # interpolated every interpolation_step


def plans_past_the_wall_with(monkeypatch, strict_radius: float | None) -> list[list[float]]:
    """Eight seeded Dubins plans past wall_map's wall end, OMPL planning with half the radius
    (0.15 m: its shortcuts hug the wall's end) and the strict margin of ``strict_radius`` (None:
    the planner's own); every result clear of the true 0.30 m. The radii of each plan's solves."""
    costmap = wall_map()
    ompl = make("Dubins", seed=1, robot_radius=0.25, clearance_distance=0.05)
    verify, _, strict = ompl._checkers(costmap)
    loose = verify.with_radius(0.15)
    if strict_radius is not None:
        strict = verify.with_radius(strict_radius)
    monkeypatch.setattr(ompl, "_checkers", lambda c: (verify, loose, strict))
    radii: list[float] = []
    original = ompl._solve

    def solve(costmap, checker, start, goal, budget):
        radii.append(checker.radius)
        return original(costmap, checker, start, goal, budget)

    monkeypatch.setattr(ompl, "_solve", solve)
    per_plan = []
    for seed in range(1, 9):
        ompl.seed = seed
        radii.clear()
        result = ompl.plan(costmap, (2.0, 2.0, 0.0), (8.0, 2.0, -math.pi / 2))
        assert result.ok, result.reason
        assert_clear(costmap, result.poses, 0.30)
        per_plan.append(list(radii))
    return per_plan


def test_a_path_failing_the_final_check_is_planned_again_with_the_strict_margin(monkeypatch):
    per_plan = plans_past_the_wall_with(monkeypatch, None)
    assert all(radii[0] == pytest.approx(0.15) for radii in per_plan)
    retried = [radii for radii in per_plan if len(radii) == 2]
    assert len(retried) >= 2
    strict = 0.30 + (0.25 + math.sqrt(2.0)) * 0.05
    assert all(radii[1] == pytest.approx(strict) for radii in retried)


def test_without_the_strict_margin_a_refused_path_is_planned_again_from_new_samples(
        monkeypatch):
    # A strict margin no start can have (as for a robot close to a wall): the retries draw new
    # samples with the same radius.
    per_plan = plans_past_the_wall_with(monkeypatch, 50.0)
    assert all(radii == [pytest.approx(0.15)] * len(radii) for radii in per_plan)
    assert sum(len(radii) > 1 for radii in per_plan) >= 2


def test_se2_poses_face_the_next_one_and_the_last_has_the_goal_yaw():
    result = make(seed=3).plan(wall_map(), (2.0, 2.0, 0.0), (8.0, 2.0, -2.0))
    assert result.ok, result.reason
    d = np.diff(result.poses[:, :2], axis=0)
    assert np.allclose(result.poses[:-1, 2], np.arctan2(d[:, 1], d[:, 0]))
    assert result.poses[-1, 2] == pytest.approx(-2.0)
    assert result.poses[:, 1].max() > 8.0  # around the wall's end


@pytest.mark.parametrize("radius", [0.5, 1.0])
def test_dubins_paths_respect_the_turning_radius_and_never_reverse(radius):
    ompl = make("Dubins", turning_radius=radius, seed=11, interpolation_step=0.05)
    result = ompl.plan(wall_map(), (2.0, 2.0, math.pi / 2), (8.0, 2.0, -math.pi / 2))
    assert result.ok, result.reason
    poses = result.poses
    step = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    turn = np.abs(np.angle(np.exp(1j * np.diff(poses[:, 2]))))
    # Curvature: a chord of an arc of radius r turns by at most step / r (chord <= arc).
    assert (turn <= step / radius * 1.02 + 1e-9).all()
    heading = np.stack([np.cos(poses[:-1, 2]), np.sin(poses[:-1, 2])], axis=1)
    assert (np.einsum("ij,ij->i", np.diff(poses[:, :2], axis=0), heading) > 0.0).all()


def test_reeds_shepp_reverses_to_a_goal_just_behind():
    ompl = make("ReedsShepp", turning_radius=1.0, seed=2, interpolation_step=0.05)
    result = ompl.plan(wall_map(), (2.0, 2.0, 0.0), (1.0, 2.0, 0.0))
    assert result.ok, result.reason
    poses = result.poses
    heading = np.stack([np.cos(poses[:-1, 2]), np.sin(poses[:-1, 2])], axis=1)
    along = np.einsum("ij,ij->i", np.diff(poses[:, :2], axis=0), heading)
    assert (along < 0.0).all()  # straight back, yaw kept
    assert result.length == pytest.approx(1.0, abs=0.01)


def test_the_same_seed_gives_the_same_path_and_another_seed_another():
    costmap = clutter_map()
    start, goal = (-0.2, -1.0, 0.0), (5.7, 3.0, 1.0)
    for space in ("SE2", "ReedsShepp"):
        first = make(space, seed=5, simplify=False).plan(costmap, start, goal)
        # Other plans in between must not matter.
        make(space, seed=0).plan(costmap, start, goal)
        again = make(space, seed=5, simplify=False).plan(costmap, start, goal)
        other = make(space, seed=6, simplify=False).plan(costmap, start, goal)
        assert first.ok and again.ok and other.ok
        assert np.array_equal(first.poses, again.poses)
        assert not np.array_equal(first.poses, other.poses)


def test_an_anytime_planner_is_repeatable_with_max_iterations():
    costmap = wall_map()
    paths = [
        OMPLGridPlanner(planner="RRTstar", seed=9, max_iterations=300, solve_time=30.0)
        .plan(costmap, (2.0, 2.0, 0.0), (8.0, 2.0, 0.0)).poses
        for _ in range(2)
    ]
    assert len(paths[0]) > 0 and np.array_equal(paths[0], paths[1])


def test_a_goal_behind_a_closed_wall_is_unreachable_at_once():
    costmap = wall_map()
    costmap.data[160:, 95:105] = 254  # the wall now closes the map
    ompl = OMPLGridPlanner(solve_time=LONG, seed=1)
    result = ompl.plan(costmap, (2.0, 2.0, 0.0), (8.0, 2.0, 0.0))
    assert not result.ok and len(result.poses) == 0
    assert result.reason == (
        "goal (8.00, 2.00) is unreachable from (2.00, 2.00): no way on the map is wide enough "
        "for the robot and its clearance (a disc of 0.43 m)"
    )
    assert ompl.last_stats.validity_checks == 0  # OMPL never ran: no LONG wait


def gap_map(gap: float) -> Costmap2D:
    """wall_map's wall closed to the top but for a gap ``gap`` m wide at y 6..6+gap."""
    costmap = wall_map()
    costmap.data[160:, 95:105] = 254
    costmap.data[120 : 120 + round(gap / 0.05), 95:105] = 0
    return costmap


@pytest.mark.parametrize(("radius", "passes"), [(0.35, False), (0.15, True)])
def test_a_gap_is_passed_exactly_when_the_disc_fits_through_it(radius, passes):
    # A 0.8 m gap: the planning disc is radius + 0.1 clearance + half a cell (0.025 m), so
    # 0.475 m (0.95 m wide) cannot pass and 0.275 m (0.55 m) can.
    costmap = gap_map(0.8)
    ompl = make(seed=2, robot_radius=radius, clearance_distance=0.1)
    result = ompl.plan(costmap, (2.0, 2.0, 0.0), (8.0, 2.0, 0.0))
    assert result.ok == passes, result.reason
    if passes:
        assert_clear(costmap, result.poses, radius + 0.1)
        crossing = result.poses[np.argmin(np.abs(result.poses[:, 0] - 5.0)), 1]
        assert 6.0 < crossing < 6.8  # through the gap
    else:
        assert "no way on the map is wide enough" in result.reason


def test_ompl_samples_only_the_box_of_the_start_region():
    # An arena 3 m x 3 m inside a 10 m map free all around it (as a voxel map's projection
    # leaves the area beyond the walls of a drawn map): every state OMPL draws is in the arena's
    # box, none in the 91 % of the map outside it.
    costmap = Costmap2D.filled(200, 200, 0.05)
    costmap.data[40:44, 40:104] = 254
    costmap.data[100:104, 40:104] = 254
    costmap.data[40:104, 40:44] = 254
    costmap.data[40:104, 100:104] = 254
    costmap.data[70:74, 44:84] = 254  # a wall inside the arena: plan around its end
    ompl = make(seed=3, robot_radius=0.15, clearance_distance=0.05)
    checker = ompl.planning_checker(costmap)
    x0, y0, x1, y1 = checker.region_extent(2.6, 2.6)
    # The arena's inside, x and y 2.2..5.0, less the disc's radius, plus a cell.
    r = checker.radius - 0.05
    assert (x0, y0, x1, y1) == pytest.approx((2.2 + r, 2.2 + r, 5.0 - r, 5.0 - r), abs=0.06)
    drawn = []
    is_free = checker.is_free

    def recording(x, y):
        drawn.append((x, y))
        return is_free(x, y)

    checker.is_free = recording
    result = ompl.plan(costmap, (2.6, 2.6, 0.0), (2.6, 4.4, 0.0))
    assert result.ok, result.reason
    points = np.array(drawn)
    assert len(points) > 2
    assert (points[:, 0] >= x0).all() and (points[:, 0] <= x1).all()
    assert (points[:, 1] >= y0).all() and (points[:, 1] <= y1).all()
    assert_clear(costmap, result.poses, 0.2)


@pytest.mark.parametrize(("space", "yaw"), [("SE2", 0.0), ("ReedsShepp", 0.0), ("Dubins", 3.0)])
def test_a_robot_inside_the_clearance_escapes_along_a_segment_its_body_clears(space, yaw):
    costmap = wall_map()
    # 0.35 m left of the wall (x 4.75): inside the 0.4 m footprint, the 0.3 m body clear. Facing
    # the wall, a Reeds-Shepp car backs out; a Dubins car (facing away) drives out ahead.
    robot = (4.40, 4.0, yaw)
    ompl = make(space, seed=4, robot_radius=0.3, clearance_distance=0.1, turning_radius=0.4)
    result = ompl.plan(costmap, robot, (2.0, 2.0, 0.0))
    assert result.ok, result.reason
    poses = result.poses
    assert poses[0, :2].tolist() == [4.40, 4.0]
    assert_clear(costmap, poses, 0.30)  # the body never touches the wall
    # It leaves the clearance first: the distance to the wall grows along the escape.
    assert poses[1, 0] < poses[0, 0]
    if space != "SE2":
        assert poses[1, 2] == pytest.approx(yaw)  # straight out along the heading, yaw kept
    # Past the escape, the footprint (body + clearance) is clear again.
    first_clear = int(np.argmax(ompl.checker(costmap).are_free(poses[:, :2])))
    assert_clear(costmap, poses[first_clear:], 0.40)


def test_a_robot_escapes_to_the_side_its_goal_is_on():
    # A thin wall across the map at y = 2 with a 0.6 m gap (x 2.7..3.3): the 0.5 m body passes,
    # the 0.7 m footprint does not, so the two halves are separate free regions. The robot
    # stands in the gap, a little south of the wall's line, facing along it: the nearest point
    # to plan from is south; the goal is north, so it escapes north through the gap.
    costmap = Costmap2D.filled(120, 80, 0.05)
    costmap.data[40, :] = 254
    costmap.data[40, 54:66] = 0
    robot, goal = (3.0, 1.97, 0.0), (3.0, 3.5, 0.0)
    ompl = make(seed=1, robot_radius=0.25, clearance_distance=0.1)
    planning = ompl.planning_checker(costmap)
    assert not planning.connected((3.0, 1.0), goal[:2])
    nearest = ompl.escape_point(costmap, *robot)
    assert nearest is not None and nearest[1] < 2.0
    result = ompl.plan(costmap, robot, goal)
    assert result.ok, result.reason
    assert result.poses[0, :2].tolist() == [3.0, 1.97]
    assert (result.poses[1:, 1] > 1.97).all()  # northwards from the first step
    assert_clear(costmap, result.poses, 0.25)


@pytest.mark.parametrize("space", ["SE2", "ReedsShepp", "Dubins"])
def test_a_goal_inside_the_clearance_is_approached_along_a_segment_its_body_clears(space):
    costmap = wall_map()
    # 0.35 m left of the wall (x 4.75), facing it: inside the 0.4 m footprint, the 0.3 m body
    # clear (a sensor hit beyond a wall can put a waypoint there). OMPL plans to a point behind
    # it along its heading; the path ends with the straight drive in.
    goal = (4.40, 4.0, 0.0)
    ompl = make(space, seed=4, robot_radius=0.3, clearance_distance=0.1, turning_radius=0.4)
    assert "goal (4.40, 4.00) is closer than" in ompl.pose_problem(costmap, 4.40, 4.0, "goal")
    result = ompl.plan(costmap, (2.0, 2.0, 0.0), goal)
    assert result.ok, result.reason
    poses, approach = result.poses, result.approach
    assert poses[-1].tolist() == pytest.approx(list(goal))
    assert approach > 0
    drive_in = poses[-approach - 1 :]
    assert (np.diff(drive_in[:, 0]) > 0).all() and (drive_in[:, 1] == 4.0).all()
    assert drive_in[:, 2] == pytest.approx(np.zeros(len(drive_in)))  # along the goal's yaw
    assert_clear(costmap, drive_in, 0.30)  # the body never touches the wall
    # OMPL's part keeps the footprint (body + clearance) clear, up to where the approach starts.
    assert_clear(costmap, poses[: len(poses) - approach], 0.40)
    assert not ompl.checker(costmap).is_free(4.40, 4.0)  # the approach is needed


@pytest.mark.parametrize("space", ["SE2", "ReedsShepp", "Dubins"])
def test_a_goal_with_its_back_to_the_wall_is_approached_from_ahead_but_not_by_a_forward_car(
    space,
):
    # As above, facing away from the wall: behind it, the wall. SE2 comes from ahead and turns
    # on the spot; Reeds-Shepp backs in along the goal's yaw; a Dubins car cannot drive in
    # forwards, and a sideways approach is no car's: refused, saying why.
    costmap = wall_map()
    goal = (4.40, 4.0, math.pi)
    ompl = make(space, seed=4, robot_radius=0.3, clearance_distance=0.1, turning_radius=0.4)
    result = ompl.plan(costmap, (2.0, 2.0, 0.0), goal)
    if space == "Dubins":
        assert not result.ok
        assert "goal (4.40, 4.00) is closer than" in result.reason
        assert "no point to plan to is within 1 m" in result.reason
        return
    assert result.ok, result.reason
    poses, approach = result.poses, result.approach
    drive_in = poses[-approach - 1 :]
    assert approach > 0 and (np.diff(drive_in[:, 0]) > 0).all()
    assert abs(poses[-1, 2]) == pytest.approx(math.pi)
    assert np.abs(drive_in[:-1, 2]) == pytest.approx(
        np.full(approach, 0.0 if space == "SE2" else math.pi)
    )
    assert_clear(costmap, drive_in, 0.30)


def test_a_start_and_a_goal_inside_the_clearance_get_an_escape_and_an_approach():
    costmap = wall_map()
    start, goal = (4.40, 2.0, 0.0), (4.40, 6.0, 0.0)
    ompl = make(seed=4, robot_radius=0.3, clearance_distance=0.1)
    result = ompl.plan(costmap, start, goal)
    assert result.ok, result.reason
    poses, approach = result.poses, result.approach
    assert poses[0].tolist()[:2] == [4.40, 2.0] and poses[-1].tolist() == pytest.approx(list(goal))
    assert_clear(costmap, poses, 0.30)
    footprint = ompl.checker(costmap).are_free(poses[:, :2])
    first_clear = int(np.argmax(footprint))
    assert 0 < first_clear < len(poses) - approach - 1
    assert_clear(costmap, poses[first_clear : len(poses) - approach], 0.40)
    assert (np.diff(poses[-approach - 1 :, 0]) > 0).all()


def gap_wall_map() -> Costmap2D:
    """6 m x 4 m at 0.05 m, a thin wall across at y 2.00..2.05 with a 0.6 m gap (x 2.7..3.3):
    a 0.25 m body passes the gap, a 0.35 m footprint does not (two free regions)."""
    costmap = Costmap2D.filled(120, 80, 0.05)
    costmap.data[40, :] = 254
    costmap.data[40, 54:66] = 0
    return costmap


def test_start_and_goal_in_the_clearance_take_an_escape_and_an_approach_into_one_region():
    # The start is 0.3 m south of the wall, 2 m from the gap: it can only escape south. The
    # goal stands in the gap, a little north: its nearest point to plan to is north, which the
    # start cannot reach; the approach comes from the south, through the gap, instead.
    costmap = gap_wall_map()
    start, goal = (1.0, 1.72, 0.0), (3.0, 2.06, 0.0)
    ompl = make(seed=1, robot_radius=0.25, clearance_distance=0.1)
    assert ompl.approach_point(costmap, goal, start[:2])[1] > 2.0  # the nearest: north
    result = ompl.plan(costmap, start, goal)
    assert result.ok, result.reason
    poses, approach = result.poses, result.approach
    assert poses[0, :2].tolist() == [1.0, 1.72] and poses[-1].tolist() == pytest.approx(list(goal))
    assert (poses[:, 1] < 2.1).all()  # never north of the wall
    drive_in = poses[-approach - 1 :]
    assert approach > 0 and (np.diff(drive_in[:, 1]) > 0).all()  # north, into the gap
    assert_clear(costmap, poses, 0.25)
    # A goal north of the wall, far from the gap: no escape and approach share a region.
    result = ompl.plan(costmap, start, (1.0, 2.33, math.pi / 2))
    assert not result.ok
    assert "start (1.00, 1.72) and goal (1.00, 2.33) both stand within the clearance" in (
        result.reason)


def test_a_goal_the_body_does_not_fit_is_refused_saying_so():
    result = make(seed=1, robot_radius=0.3).plan(wall_map(), (2.0, 2.0, 0.0), (4.5, 2.0, 0.0))
    assert not result.ok
    assert "goal (4.50, 2.00) is closer than robot_radius (0.30 m)" in result.reason
    assert "does not fit" in result.reason


@pytest.mark.parametrize("space", ["SE2", "ReedsShepp", "Dubins"])
def test_a_goal_facing_minus_x_is_planned_to(space):
    # A yaw of exactly pi (a quaternion (0, 0, 1, 0)) is outside OMPL's [-pi, pi) SO2 bounds:
    # the goal was once "invalid" and the plan failed.
    ompl = make(space, seed=4, robot_radius=0.3, clearance_distance=0.1, turning_radius=0.4)
    for start, goal in (((2.0, 6.0, 0.0), (2.0, 2.0, math.pi)), ((2.0, 2.0, math.pi), (3, 6, 0))):
        result = ompl.plan(wall_map(), start, goal)
        assert result.ok, result.reason
        assert result.poses[-1, :2].tolist() == pytest.approx(list(goal[:2]))


def test_a_robot_touching_an_obstacle_has_no_escape():
    result = make(seed=1).plan(wall_map(), (4.55, 4.0, 0.0), (2.0, 2.0, 0.0))
    assert not result.ok and "start (4.55, 4.00) is closer than" in result.reason


@pytest.mark.parametrize(
    ("goal", "start", "words"),
    [
        ((5.0, 2.0), (2.0, 2.0), "goal (5.00, 2.00) is inside an obstacle"),
        ((4.5, 2.0), (2.0, 2.0), "goal (4.50, 2.00) is closer than robot_radius"),
        ((12.0, 2.0), (2.0, 2.0), "goal (12.00, 2.00) is outside the map [0.00, 10.00]"),
        ((8.0, 2.0), (0.1, 2.0), "start (0.10, 2.00) is closer than robot_radius"),
        ((8.0, 2.0), (5.0, 2.0), "start (5.00, 2.00) is inside an obstacle"),
        ((math.nan, 2.0), (2.0, 2.0), "not finite"),
    ],
)
def test_impossible_goals_and_starts_are_named(goal, start, words):
    result = make(seed=1).plan(wall_map(), (*start, 0.0), (*goal, 0.0))
    assert not result.ok and words in result.reason


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"state_space": "SE3"}, "state_space"),
        ({"planner": "Astar"}, "planner"),
        ({"planner": "FMT", "state_space": "Dubins"}, "FMT"),
        ({"planner": "AORRTC", "state_space": "Dubins"}, "symmetric"),
        ({"planner": "PRMstar", "state_space": "Dubins"}, "symmetric"),
        ({"solve_time": 0.0}, "solve_time"),
        ({"turning_radius": math.nan}, "turning_radius"),
        ({"seed": -1}, "seed"),
        ({"obstacle_cost": 300}, "obstacle_cost"),
        ({"planner": "PRM", "max_iterations": 10}, "second thread"),
        ({"preferred_clearance": -0.1}, "preferred_clearance"),
    ],
)
def test_bad_parameters_are_named(kwargs, words):
    with pytest.raises(ValueError, match=words):
        OMPLGridPlanner(**kwargs)


def pillars_map() -> Costmap2D:
    """6 m x 4 m at 0.05 m: two 0.8 m square pillars (x 2.1..2.9; y 0.8..1.6 and 2.4..3.2), a
    0.8 m passage between them."""
    costmap = Costmap2D.filled(120, 80, 0.05)
    costmap.data[16:32, 42:58] = 254
    costmap.data[48:64, 42:58] = 254
    return costmap


def body_distances(costmap: Costmap2D, xy: np.ndarray) -> np.ndarray:
    """Distance (m) from each point to the nearest obstacle cell centre (brute force)."""
    centres = obstacle_centres(costmap)
    return np.hypot(xy[:, None, 0] - centres[None, :, 0], xy[:, None, 1] - centres[None, :, 1]
                    ).min(axis=1)


def test_preferred_clearance_moves_se2_paths_off_the_pillars_they_round():
    # Diagonally through the 0.8 m passage between two pillars: the shortest path cuts from the
    # lower pillar's corner to the upper one's at the footprint (0.25 m, the planning margin
    # adds a little). Centred (0.35 m wanted beyond the 0.15 m body: more than the passage has)
    # it crosses the passage along its middle, straight, and keeps more room everywhere.
    costmap = pillars_map()
    start, goal = (1.2, 1.2, 0.0), (3.8, 2.8, 0.0)
    shortest = make(seed=1, robot_radius=0.15, clearance_distance=0.1).plan(
        costmap, start, goal)
    centred = make(seed=1, robot_radius=0.15, clearance_distance=0.1,
                   preferred_clearance=0.35).plan(costmap, start, goal)
    assert shortest.ok and centred.ok
    assert_clear(costmap, centred.poses, 0.25)
    near = body_distances(costmap, shortest.poses[:, :2]).min()
    assert near < 0.35
    # The middle of the passage is 0.4 m from the pillars' faces, 0.425 m from their cells'
    # centres.
    poses = centred.poses
    passage = np.abs(poses[:, 0] - 2.5) < 0.4
    assert passage.sum() >= 7
    assert np.abs(poses[passage, 1] - 2.0).max() < 0.01
    assert np.abs(poses[passage, 2]).max() < 0.05  # no zigzag: every pose faces along it
    assert body_distances(costmap, poses[:, :2]).min() > near + 0.05
    # The poses are still interpolation_step apart at most, SE2 poses facing the next one.
    xy = poses[:, :2]
    assert np.hypot(*np.diff(xy, axis=0).T).max() <= 0.1 + 1e-9
    d = np.diff(xy, axis=0)
    np.testing.assert_allclose(poses[:-1, 2], np.arctan2(d[:, 1], d[:, 0]))
    assert xy[0].tolist() == [1.2, 1.2] and xy[-1].tolist() == [3.8, 2.8]


def test_a_map_one_cell_high_gives_a_reason_not_an_exception():
    result = make(seed=1, preferred_clearance=0.3).plan(
        Costmap2D.filled(50, 1, 0.05), (0.5, 0.02, 0.0), (2.0, 0.02, 0.0))
    assert not result.ok and "closer than robot_radius" in result.reason


def test_preferred_clearance_leaves_car_paths_and_the_shortest_setting_alone():
    costmap = pillars_map()
    start, goal = (1.5, 0.5, 0.0), (4.5, 3.5, 0.0)
    for space, preferred in (("Dubins", 0.35), ("ReedsShepp", 0.35), ("SE2", 0.1)):
        plain = make(space, seed=1, robot_radius=0.15, clearance_distance=0.1).plan(
            costmap, start, goal)
        moved = make(space, seed=1, robot_radius=0.15, clearance_distance=0.1,
                     preferred_clearance=preferred).plan(costmap, start, goal)
        assert plain.ok and moved.ok, (space, plain.reason, moved.reason)
        np.testing.assert_array_equal(plain.poses, moved.poses)


def test_every_planner_offered_finds_a_path_in_se2():
    costmap = wall_map()
    for name in PLANNERS:
        planner = OMPLGridPlanner(planner=name, **bounded(name), seed=3)
        result = planner.plan(costmap, (2.0, 2.0, 0.0), (8.0, 2.0, 0.0))
        assert result.ok, f"{name}: {result.reason}"
        assert_clear(costmap, result.poses, 0.4)
