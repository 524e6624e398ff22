"""SerestController without ROS: tracking, goal zone, safety speed, limits, NavState I/O."""

from __future__ import annotations

import importlib
import math

import numpy as np
import pytest
from closed_loop import (
    Clock,
    Limits,
    assert_within_limits,
    curved_path,
    distance_to_path,
    make_plugin,
    run_closed_loop,
    set_path,
    set_pose,
    straight_path,
)

from easynav.common.sensors import PointPerception
from easynav.controllers.obstacle_distance import RobotWay, closest_lethal_distance
from easynav.controllers.serest_controller import SerestController
from easynav.controllers.serest_tracker import SEREST_DEFAULTS, TURN_PROBE_STEP, SerestTracker
from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.plugins.compatibility import compatibility_errors
from easynav.core.robot import RobotLimits
from easynav.core.types import LETHAL_OBSTACLE, Costmap2D, TwistStamped

LIMITS = RobotLimits(max_linear_vel=0.5, max_angular_vel=1.0)
DT = 0.05


def s_path() -> np.ndarray:
    xs = np.arange(0.0, 3.001, 0.05)
    path = np.column_stack((xs, 0.5 * np.sin(1.5 * xs), np.zeros_like(xs)))
    path[-1, 2] = -math.pi / 2  # a goal yaw far from the last segment's heading
    return path


def make(params=None, limits=LIMITS, clock=None):
    return make_plugin(SerestController, "serest", params, limits, clock)


def loop_state(path, free=True):
    nav_state = NavState()
    set_path(nav_state, path)
    nav_state.set("map", Costmap2D.filled(200, 200, 0.05, -5.0, -5.0))
    return nav_state


def test_safe_speed_and_curvature_formulas():
    tracker = SerestTracker()
    p = SEREST_DEFAULTS
    d = 1.0
    expected = math.sqrt(2 * p["a_brake"] * (d - p["d0_margin"])) - p["tau_latency"] * p["a_brake"]
    assert tracker.v_safe(d) == pytest.approx(expected)
    assert tracker.v_safe(0.2) == 0.0 and tracker.v_safe(math.inf) == math.inf


def test_projection_and_frenet_errors():
    tracker = SerestTracker()
    path = straight_path()
    out = tracker.step(path, (1.0, 0.2, 0.1), DT, LIMITS, pos_tol=0.05, yaw_tol=0.05)
    assert out.debug["e_y"] == pytest.approx(0.2)
    assert out.debug["e_theta"] == pytest.approx(0.1)
    assert out.debug["dist_to_end"] == pytest.approx(2.0)
    assert out.w < 0.0  # left of the path and heading left: turn right


@pytest.mark.parametrize(
    ("make_path", "deviation"), [(straight_path, 0.05), (curved_path, 0.1), (s_path, 0.2)]
)
def test_follows_the_path_and_stops_at_the_goal(make_path, deviation):
    clock = Clock()
    serest = make({}, LIMITS, clock)
    path = make_path()
    nav_state = loop_state(path)
    nav_state.set("goal_tolerance.position", 0.08)
    nav_state.set("goal_tolerance.yaw", 0.05)
    run = run_closed_loop(serest, nav_state, clock, dt=DT, t_max=60.0)
    assert run.arrived
    x, y, yaw = run.final
    assert math.hypot(x - path[-1, 0], y - path[-1, 1]) <= 0.08
    assert abs(math.remainder(yaw - path[-1, 2], 2 * math.pi)) <= 0.05
    assert max(distance_to_path(path, px, py) for px, py, _ in run.poses) <= deviation
    assert_within_limits(run, LIMITS, DT, allow_reverse=False)
    assert nav_state.get("serest.debug.goal.arrived") == 1


def test_slows_for_an_obstacle_in_the_costmap_and_brakes_in_an_emergency():
    clock = Clock()
    serest = make({}, LIMITS, clock)
    path = straight_path()
    nav_state = loop_state(path)
    costmap = nav_state.get("map")
    ix, iy = costmap.world_to_cell(1.0, 0.0)
    costmap.data[iy, ix] = LETHAL_OBSTACLE
    # Cell [1.0, 1.05] x [0, 0.05]: centre (1.025, 0.025), minus half a cell.
    near = math.hypot(1.025, 0.025) - 0.025
    assert closest_lethal_distance(costmap, 0.0, 0.0, 2.0) == pytest.approx(near)
    assert closest_lethal_distance(costmap, 0.0, 0.0, 0.9) == math.inf
    run = run_closed_loop(serest, nav_state, clock, dt=DT, t_max=10.0)
    xs = [x for x, _, _ in run.poses]
    # v_safe reaches 0 at d0_margin (0.3 m) from the cell's near edge (1.0 m): x <= 0.7.
    assert 0.5 < max(xs) <= 0.7 + 1e-6
    assert run.commands[-1][0] < 0.01  # creeping to a stop
    assert nav_state.get("serest.debug.d_closest") < 0.4


def test_only_cells_in_the_way_count():
    costmap = Costmap2D.filled(80, 80, 0.05, -2.0, -2.0)
    for x, y in ((1.01, 0.11), (0.01, 0.51), (-0.59, 0.01)):  # ahead, beside, behind
        ix, iy = costmap.world_to_cell(x, y)
        costmap.data[iy, ix] = LETHAL_OBSTACLE
    ahead = math.hypot(1.025, 0.125) - 0.025
    beside = math.hypot(0.025, 0.525) - 0.025
    behind = math.hypot(0.575, 0.025) - 0.025
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5) == pytest.approx(beside)
    # Driving straight on along +x with a 0.3 m radius: the cell ahead only; along -x, the
    # one behind; along -y, none.
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5, RobotWay(0.0, half_width=0.3)) == (
        pytest.approx(ahead)
    )
    backwards = RobotWay(math.pi, half_width=0.3)
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5, backwards) == pytest.approx(behind)
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5, RobotWay(-math.pi / 2, 0.0, None, 0.3)
                                   ) == math.inf
    # Turning left on a 0.2625 m radius, the robot passes over the cell beside it (the arc's
    # top is at (0, 0.525)); turning right it does not (the cell ahead is still in its way
    # straight on); a path ahead leading to it counts it too.
    left = RobotWay(0.0, curvature=1 / 0.2625, half_width=0.1)
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5, left) == pytest.approx(beside)
    right = RobotWay(0.0, curvature=-1 / 0.2625, half_width=0.1)
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5, right) == pytest.approx(ahead)
    to_it = RobotWay(-math.pi / 2, 0.0, np.array([[0.0, 0.0], [0.0, 0.8]]), 0.1)
    assert closest_lethal_distance(costmap, 0.0, 0.0, 1.5, to_it) == pytest.approx(beside)


def test_drives_past_an_obstacle_beside_the_path_within_d0_margin():
    # A wall 0.35 m beside a straight path (cells centred 0.375 m off it), d0_margin 0.4 m: the
    # original's direction-free distance gave a safe speed of 0 from the start, for ever. The
    # wall is outside the strip the robot (radius 0.3 m) sweeps, so it does not slow it.
    clock = Clock()
    serest = make({"d0_margin": 0.4}, LIMITS, clock)
    path = straight_path()
    nav_state = loop_state(path)
    nav_state.set("goal_tolerance.position", 0.08)
    nav_state.set("goal_tolerance.yaw", 0.05)
    costmap = nav_state.get("map")
    for x in np.arange(-0.5, 3.5, 0.05):
        ix, iy = costmap.world_to_cell(x, 0.375)
        costmap.data[iy, ix] = LETHAL_OBSTACLE
    run = run_closed_loop(serest, nav_state, clock, dt=DT, t_max=30.0)
    assert run.arrived
    assert max(v for v, _ in run.commands) > 0.45


def bend_path(radius: float = 0.8) -> np.ndarray:
    """1 m straight along +x, then a left half turn of ``radius``."""
    straight = np.column_stack((np.arange(0.0, 1.0, 0.05), np.zeros(20)))
    a = np.arange(0.0, math.pi, 0.05 / radius)
    arc = np.column_stack((1.0 + radius * np.sin(a), radius * (1.0 - np.cos(a))))
    xy = np.vstack((straight, arc))
    return np.column_stack((xy, np.arctan2(np.gradient(xy[:, 1]), np.gradient(xy[:, 0]))))


def test_stops_short_of_an_obstacle_on_a_bend_of_the_path():
    # A cell 0.15 m outside the bend, 1 m along the arc: off the straight line ahead of the
    # robot until it is near, in its way as it follows the path. At 1 m/s, counting only the
    # straight line ahead, the robot saw it 0.4 m off with 0.8 m needed to stop, and ran
    # 11 cm into it. It stops d0_margin (0.3 m) short of it.
    clock = Clock()
    limits = RobotLimits(max_linear_vel=1.0, max_angular_vel=1.5, max_linear_acc=1.0)
    serest = make({"v_ref": 1.0}, limits, clock)
    nav_state = loop_state(bend_path())
    costmap = nav_state.get("map")
    a = 1.0 / 0.8
    ix, iy = costmap.world_to_cell(1.0 + 0.95 * math.sin(a), 0.8 - 0.95 * math.cos(a))
    costmap.data[iy, ix] = LETHAL_OBSTACLE
    cx, cy = costmap.cell_to_world(ix, iy)
    run = run_closed_loop(serest, nav_state, clock, dt=DT, t_max=15.0)
    nearest = min(math.hypot(x - cx, y - cy) for x, y, _ in run.poses) - 0.025
    assert nearest > SEREST_DEFAULTS["d0_margin"] - 0.01
    assert max(v for v, _ in run.commands) > 0.9  # at full speed on the straight


def test_point_perceptions_are_turned_into_the_map_frame():
    clock = Clock()
    serest = make({}, LIMITS, clock)
    nav_state = NavState()
    # The robot faces +y; the path runs along +y.
    set_path(nav_state, np.column_stack((np.zeros(41), np.arange(0.0, 2.01, 0.05),
                                         np.full(41, math.pi / 2))))
    set_pose(nav_state, 0.0, 0.0, math.pi / 2)
    nav_state.set("map", "a map of any other type")
    nav_state.set_group("points", ["a_grouped_sensor"])
    # In the robot's frame: ahead (x = 0.8), and on its right (y = -0.6), not in its way.
    scan = np.array([[0.8, 0.05, 0.2], [0.0, -0.6, 0.2]])
    nav_state.set("scan", PointPerception(scan, "base_footprint", clock.t))
    serest.update_rt(nav_state)
    assert nav_state.get("serest.debug.d_closest") == pytest.approx(math.hypot(0.8, 0.05))


def test_the_walls_of_an_occupancy_grid_map_are_obstacles():
    # The simple maps manager writes a SimpleMap (boolean cells) in `map`, not a Costmap2D.
    from test_map_as_costmap import OccupancyCells

    serest = make({}, LIMITS, Clock())
    cells = np.zeros((50, 60), dtype=bool)
    cells[25, 20] = True  # the cell [1.0, 1.1) x [0.0, 0.1)
    nav_state = NavState()
    nav_state.set("map", OccupancyCells(cells, resolution=0.1, origin_x=-1.0, origin_y=-2.5))
    near = math.hypot(1.05, 0.05) - 0.05
    assert serest.obstacle_distance(nav_state, 0.0, 0.0, 0.0) == pytest.approx(near)


def test_a_static_map_and_the_point_perceptions_count_both():
    # A GridMap (the GridMap stack) holds no live obstacle: a nearer point ahead counts too.
    gridmap = pytest.importorskip("easynav.maps.gridmap")
    clock = Clock()
    serest = make({}, LIMITS, clock)
    elevation = np.zeros((50, 60))
    elevation[20:30, 22:27] = 2.0  # a block from x = 1.2 m on, ahead of the robot at (0, 0)
    nav_state = NavState()
    nav_state.set("map", gridmap.GridMap.from_elevation(elevation, 0.1, -1.0, -2.5))
    from_map = serest.obstacle_distance(nav_state, 0.0, 0.0, 0.0)
    assert from_map == pytest.approx(1.1, abs=0.01)  # its steep ring, a cell outside it
    nav_state.set("scan", PointPerception(np.array([[0.8, 0.05, 0.2]]), "base_footprint",
                                          clock.t))
    assert serest.obstacle_distance(nav_state, 0.0, 0.0, 0.0) == from_map  # no points group
    nav_state.set_group("points", ["a_grouped_sensor"])
    assert serest.obstacle_distance(nav_state, 0.0, 0.0, 0.0) == pytest.approx(
        math.hypot(0.8, 0.05))


def test_closest_obstacle_distance_key_overrides_the_map():
    clock = Clock()
    serest = make({}, LIMITS, clock)
    nav_state = loop_state(straight_path())
    set_pose(nav_state, 0.0, 0.0, 0.0)
    nav_state.set("closest_obstacle_distance", 0.1)
    serest.update_rt(nav_state)
    assert serest.state == "emergency"
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()


def test_without_map_the_command_is_zero():
    clock = Clock()
    serest = make({}, LIMITS, clock)
    nav_state = NavState()
    set_path(nav_state, straight_path())
    set_pose(nav_state, 0.0, 0.0, 0.0)
    serest.update_rt(nav_state)
    assert serest.state == "no_map"
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()


#: The maps managers that write NavState ``map`` (module, class) and the one that does not.
WRITES_MAP = (
    ("simple_maps_manager", "SimpleMapsManager"),
    ("costmap.costmap_maps_manager", "CostmapMapsManager"),
    ("voxel.octomap_maps_manager", "OctomapMapsManager"),
    ("voxel.bonxai_maps_manager", "BonxaiMapsManager"),
    ("gridmap.gridmap_maps_manager", "GridmapMapsManager"),
)


def test_beside_a_maps_manager_without_a_navstate_map_configure_refuses_it():
    # Beside the NavMap maps manager alone (it writes ``map.navmap``) SeReST never moved: the
    # compatibility check of configure, so of ``easynav check``, refuses the pair, naming both.
    pytest.importorskip("easynav.maps")

    def errors_beside(module: str, name: str) -> list[str]:
        cls = getattr(importlib.import_module(f"easynav.maps.{module}"), name)
        return compatibility_errors({
            "maps_manager_node": [("maps", f"pkg/{name}", cls)],
            "controller_node": [("serest", "easynav_serest_controller/SerestController",
                                 SerestController)],
        })

    for module, name in WRITES_MAP:
        assert errors_beside(module, name) == [], name
    assert errors_beside("navmap.navmap_maps_manager", "NavMapMapsManager") == [
        "controller_node.serest [easynav_serest_controller/SerestController] needs a map of "
        "type simple_map or costmap or gridmap, but maps_manager_node.maps "
        "[pkg/NavMapMapsManager] provides navmap"
    ]


def test_runtime_limit_and_parameter_changes_take_effect_at_once():
    clock = Clock()
    limits = Limits(LIMITS)
    serest = make({}, limits, clock)
    nav_state = loop_state(straight_path())
    run = run_closed_loop(serest, nav_state, clock, dt=DT, t_max=3.0)
    assert max(v for v, _ in run.commands) > 0.45
    limits.value = RobotLimits(max_linear_vel=0.15, max_angular_vel=0.5)
    serest.apply_parameter("v_ref", 0.1)
    run = run_closed_loop(serest, nav_state, clock, start=run.final, dt=DT, t_max=1.0)
    speeds = [v for v, _ in run.commands]
    assert max(speeds) <= 0.15 + 1e-9  # the new limit from the first command on
    assert np.mean(speeds[-5:]) <= 0.11  # and the new reference speed


def test_deprecated_limits_are_left_to_controller_node():
    serest = make({"max_linear_speed": 0.3, "max_angular_acc": 0.5})
    assert serest.params.max_linear_speed == 0.3 and serest.params.max_angular_acc == 0.5
    assert SerestController.DEPRECATED_LIMITS["max_angular_acc"] == "max_angular_acc"
    assert serest.limits() == LIMITS


def test_turns_in_place_when_facing_away_from_the_path():
    clock = Clock()
    serest = make({}, LIMITS, clock)
    nav_state = loop_state(straight_path())
    set_pose(nav_state, 0.0, 0.0, 2.0)
    serest.update_rt(nav_state)
    cmd = nav_state.get("cmd_vel", TwistStamped).twist
    assert serest.state == "turn_in_place" and cmd.vx == 0.0 and cmd.wz < 0.0


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"ell": 0.0}, "serest.ell = 0.0: must be > 0"),
        ({"allow_reverse": "yes"}, "serest.allow_reverse = 'yes': must be true or false"),
        ({"corner_min_alpha": 2.0}, "serest.corner_min_alpha = 2.0"),
    ],
)
def test_bad_parameters_fail_configuration(params, message):
    with pytest.raises(PluginConfigurationError, match=message):
        make(params)


def test_point_perceptions_count_only_when_a_points_group_exists():
    clock = Clock()
    serest = make({}, LIMITS, clock)
    nav_state = NavState()
    set_path(nav_state, straight_path())
    set_pose(nav_state, 0.0, 0.0, 0.0)
    nav_state.set("map", "a map of any other type")  # required, but not a Costmap2D
    # Ahead, beside (nearer, but not in the way of a 0.3 m robot driving on), out of range.
    scan = np.array([[0.8, 0.2, 0.2], [0.1, 0.6, 0.2], [3.0, 0.0, 0.2]])
    nav_state.set("scan", PointPerception(scan, "base_footprint", clock.t))
    serest.update_rt(nav_state)
    assert nav_state.get("serest.debug.d_closest") == math.inf
    nav_state.set_group("points", ["a_grouped_sensor"])
    clock.t += DT
    serest.update_rt(nav_state)
    # 0.3 m voxels: the point (0.8, 0.2) stays the first of its voxel.
    assert nav_state.get("serest.debug.d_closest") == pytest.approx(math.hypot(0.8, 0.2))


def test_path_curvature_is_the_turn_around_the_projection():
    # A densely sampled arc of radius 0.5 m: 2 1/m wherever the window is on the arc.
    a = np.arange(0.0, math.pi / 2 + 1e-9, 0.02)
    pts = np.column_stack((0.5 * np.sin(a), 0.5 * (1.0 - np.cos(a))))
    s_acc = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    assert SerestTracker.path_curvature(pts, s_acc, 0.4, 0.15) == pytest.approx(2.0, rel=0.02)
    # Clockwise: negative. A straight path: 0. One sharp vertex: its turn over the window.
    mirrored = pts * (1.0, -1.0)
    assert SerestTracker.path_curvature(mirrored, s_acc, 0.4, 0.15) == pytest.approx(-2.0, rel=0.02)
    line = np.column_stack((np.arange(0.0, 2.0, 0.1), np.zeros(20)))
    line_s = np.arange(0.0, 2.0, 0.1)
    assert SerestTracker.path_curvature(line, line_s, 1.0, 0.15) == 0.0
    corner = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)])
    assert SerestTracker.path_curvature(corner, np.array([0.0, 1.0, 2.0]), 1.0, 0.15) == \
        pytest.approx((math.pi / 2) / 0.3)
    # The window is clipped to the path: near its ends, over what is left.
    assert SerestTracker.path_curvature(corner, np.array([0.0, 1.0, 2.0]), 0.0, 0.15) == 0.0


#: The OMPL path of a TurtleBot3-sandbox matrix row (easynav_bonxai_maps_manager, MH-AMCL,
#: OMPL, SeReST) from its waypoint at (1.7, 0): north, a 97 degree turn west in 0.5 m below
#: the pillar at (1.0-1.35, 0.9-1.25), west, then south between two pillars.
SANDBOX_OMPL_PATH = [
    (1.72, 0.13), (1.74, 0.22), (1.71, 0.31), (1.64, 0.39), (1.57, 0.45), (1.48, 0.48),
    (1.38, 0.49), (1.28, 0.51), (1.19, 0.52), (1.09, 0.52), (0.99, 0.52), (0.89, 0.51),
    (0.79, 0.51), (0.7, 0.47), (0.64, 0.4), (0.61, 0.31), (0.6, 0.21), (0.6, 0.12),
    (0.6, 0.02), (0.6, -0.08), (0.61, -0.18), (0.61, -0.28), (0.61, -0.38), (0.6, -0.47),
    (0.6, -0.57), (0.59, -0.67), (0.59, -0.77), (0.59, -0.87), (0.59, -0.96), (0.6, -1.06),
    (0.6, -1.16), (0.59, -1.26), (0.58, -1.36), (0.58, -1.46), (0.57, -1.55), (0.55, -1.65),
]


@pytest.mark.parametrize("start_yaw", [-2.5, -1.0, 1.57])
def test_follows_a_densely_sampled_tight_turn_without_running_wide(start_yaw):
    # The original's curvature, blended at the current segment's two vertices, saw 0.08 1/m on
    # this path's turn (97 degrees over five vertices): the robot ran wide towards the pillar
    # and, from two of these three starts, stood 0.05 m from it for good (its heading and
    # lateral errors balanced on an approach the pillar blocked); from the third it passed it
    # at 0.01 m. The path's own curvature around the projection is the floor now.
    from easynav.core.robot import RobotGeometry

    clock = Clock()
    limits = RobotLimits(max_linear_vel=0.5, max_angular_vel=1.0, max_linear_acc=0.5,
                         max_linear_decel=1.0, max_angular_acc=1.0, max_angular_decel=2.0)
    serest = make({"v_ref": 0.5, "d0_margin": 0.2, "d_hard": 0.05, "slow_radius": 0.6},
                  limits, clock)
    serest.context.robot_geometry = lambda: RobotGeometry(radius=0.15, inscribed_radius=0.15)
    xy = np.array(SANDBOX_OMPL_PATH)
    yaw = np.arctan2(np.diff(xy[:, 1], append=xy[-1, 1]), np.diff(xy[:, 0], append=xy[-1, 0]))
    yaw[-1] = yaw[-2]
    nav_state = loop_state(np.column_stack((xy, yaw)))
    costmap = nav_state.get("map")
    pillars = []
    for x0, y0 in ((1.0, 0.9), (-0.15, -0.15)):  # the two pillars beside the path, 0.3 m wide
        for x in np.arange(x0 + 0.025, x0 + 0.35, 0.05):
            for y in np.arange(y0 + 0.025, y0 + 0.35, 0.05):
                ix, iy = costmap.world_to_cell(x, y)
                costmap.data[iy, ix] = LETHAL_OBSTACLE
                pillars.append(costmap.cell_to_world(ix, iy))
    pillars = np.array(pillars)
    run = run_closed_loop(serest, nav_state, clock, start=(1.70, 0.13, start_yaw), dt=DT,
                          t_max=40.0)
    assert run.arrived, run.final
    poses = np.array(run.poses)
    gaps = np.hypot(poses[:, None, 0] - pillars[None, :, 0],
                    poses[:, None, 1] - pillars[None, :, 1])
    clearance = float(gaps.min()) - 0.025 - 0.15  # to the cells' edges, less the robot's radius
    assert clearance > 0.12, clearance


def test_brakes_for_a_densely_sampled_right_angle_ahead():
    # 3 m east then 3 m north, a pose every 5 cm, at up to 1 m/s: the curvature at the
    # projection alone rises 0.15 m before the corner, too late to shed the speed (0.44 m past
    # the corner; 0.55 m with the original's blend). The turn speed ahead brakes in time.
    clock = Clock()
    limits = RobotLimits(max_linear_vel=1.0, max_angular_vel=1.0)
    serest = make({"v_ref": 1.0}, limits, clock)
    east = np.column_stack((np.arange(0.0, 3.0, 0.05), np.zeros(60)))
    north = np.column_stack((np.full(61, 3.0), np.arange(0.0, 3.001, 0.05)))
    xy = np.vstack((east, north))
    path = np.column_stack((xy, np.full(len(xy), 0.0)))
    path[60:, 2] = math.pi / 2
    nav_state = loop_state(path)
    run = run_closed_loop(serest, nav_state, clock, dt=DT, t_max=30.0)
    assert run.arrived
    assert max(distance_to_path(path, x, y) for x, y, _ in run.poses) < 0.15
    assert max(v for v, _ in run.commands) > 0.9  # full speed on the straight legs
    steps = zip(run.poses, run.commands, strict=True)
    speed_at_corner = min(v for (x, y, _), (v, _) in steps if math.hypot(x - 3.0, y) < 0.3)
    assert speed_at_corner < 0.6


def test_turn_speed_ahead_allows_braking_to_each_turn():
    tracker = SerestTracker()
    limits = RobotLimits(max_linear_vel=1.0, max_angular_vel=1.0, max_linear_decel=1.0)
    corner = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)])
    s_acc = np.array([0.0, 1.0, 2.0])
    tracker.last_v = 1.0  # braking distance 0.5 m: the corner, 1 m ahead, is out of reach
    assert tracker.turn_speed_ahead(corner, s_acc, 0.0, limits) == math.inf
    # 0.5 m before it the window's edge reaches it (kappa 2.5 1/m capped: 0.4 m/s there).
    near = tracker.turn_speed_ahead(corner, s_acc, 0.5, limits)
    v_turn = min(1.0 / 2.5, math.sqrt(SEREST_DEFAULTS["a_lat_soft"] / 2.5))
    assert v_turn < near < math.sqrt(v_turn ** 2 + 2.0 * 1.0 * 0.5)
    # On the corner: the curvature there is the command's own business; the first point
    # ahead (TURN_PROBE_STEP) still sees the capped curvature.
    on = tracker.turn_speed_ahead(corner, s_acc, 1.0, limits)
    assert on == pytest.approx(math.sqrt(v_turn ** 2 + 2.0 * 1.0 * TURN_PROBE_STEP))


def test_nearly_repeated_poses_do_not_turn_the_path():
    # A pose 0.1 um before the corner: its heading from the previous one is noise (here a turn
    # of -135 degrees, then +225), which read as a right turn of the capped curvature.
    pts = SerestTracker._clean(np.array([(0.0, 0.0), (1.0, 0.0), (1.0 - 1e-7, -1e-7),
                                         (1.0, 1.0)]), (0.0, 0.0))
    s_acc = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    assert SerestTracker.path_curvature(pts, s_acc, 1.0, 0.15) == pytest.approx(
        (math.pi / 2) / 0.3, rel=1e-3)
