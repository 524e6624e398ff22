"""Regulated Pure Pursuit without ROS: regulation laws, closed loop on a unicycle, the plugin."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.controllers.regulated_pp.dynamic_window import select_command, velocity_window
from easynav.controllers.regulated_pp.path_geometry import (
    carrot_point,
    cusp_indices,
    project_on_path,
)
from easynav.controllers.regulated_pp.regulated_pp_controller import (
    RegulatedPurePursuitController,
)
from easynav.controllers.regulated_pp.regulated_pure_pursuit import (
    ARRIVED,
    FOLLOWING,
    ROTATING_TO_HEADING,
    RegulatedPurePursuit,
)
from easynav.controllers.regulated_pp.regulation import (
    approach_limited_speed,
    corridor_clearance,
    curvature_limited_speed,
    obstacle_limited_speed,
    rotation_speed,
    scaled_lookahead,
)
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import (
    LETHAL_OBSTACLE,
    Costmap2D,
    Header,
    Odometry,
    Path,
    Pose,
    TwistStamped,
    normalize_angle,
)

_namespaces = itertools.count()
LIMITS = RobotLimits(max_linear_vel=0.5, min_linear_vel=-0.3, max_angular_vel=1.5,
                     max_linear_acc=1.0, max_linear_decel=1.5, max_angular_acc=2.0,
                     max_angular_decel=3.0)


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def make_controller(params=None, limits=LIMITS, clock=None):
    values = {"rpp.rt_freq": 20.0}
    values.update({f"rpp.{k}": v for k, v in (params or {}).items()})
    holder = {"limits": limits}
    context = PluginContext(
        parameters=DictParameters(values),
        namespace=f"rpp_test_{next(_namespaces)}",
        now=clock or Clock(),
        robot_limits=lambda: holder["limits"],
    )
    controller = RegulatedPurePursuitController()
    controller.initialize(context, "rpp")
    controller.limits_holder = holder
    return controller


def set_pose(nav_state, x, y, yaw):
    nav_state.set("robot_pose", Odometry(Header(0.0, "map"), "base_footprint",
                                         Pose.from_xy_yaw(x, y, yaw)))


def straight_path(length=4.0, step=0.05):
    xs = np.arange(0.0, length + 1e-9, step)
    return np.column_stack((xs, np.zeros_like(xs), np.zeros_like(xs)))


def arc_path(radius=1.5, angle=math.pi / 2, step=0.05):
    n = int(radius * angle / step) + 1
    a = np.linspace(0.0, angle, n)
    return np.column_stack((radius * np.sin(a), radius * (1.0 - np.cos(a)), a))


def distance_to_polyline(path_xy, point):
    _seg, _t, projection = project_on_path(path_xy, np.asarray(point), 0, len(path_xy) - 1)
    return float(np.hypot(*(projection - point)))


def run_closed_loop(controller, path_xy_yaw, start, steps=1200, dt=0.05, nav_state=None,
                    clock=None, on_step=None):
    """Simulate a unicycle driven by the plugin; returns poses, commands, states."""
    clock = clock or controller.context.now
    nav_state = nav_state or NavState()
    nav_state.set("path", Path.from_xy_yaw(path_xy_yaw, Header(0.0, "map")))
    x, y, yaw = start
    poses, commands, states = [], [], []
    for _ in range(steps):
        set_pose(nav_state, x, y, yaw)
        controller.update_rt(nav_state)
        cmd = nav_state.get("cmd_vel", TwistStamped).twist
        poses.append((x, y, yaw))
        commands.append((cmd.vx, cmd.wz))
        states.append(controller.state)
        if on_step is not None:
            on_step(controller, (x, y, yaw), (cmd.vx, cmd.wz))
        if controller.state == ARRIVED:
            break
        yaw_mid = yaw + 0.5 * cmd.wz * dt
        x += cmd.vx * math.cos(yaw_mid) * dt
        y += cmd.vx * math.sin(yaw_mid) * dt
        yaw = normalize_angle(yaw + cmd.wz * dt)
        clock.t += dt
    return np.array(poses), np.array(commands), states


def assert_within_limits(commands, limits=LIMITS):
    assert np.all(commands[:, 0] <= limits.max_linear_vel + 1e-9)
    assert np.all(commands[:, 0] >= limits.min_linear_vel - 1e-9)
    assert np.all(np.abs(commands[:, 1]) <= limits.max_angular_vel + 1e-9)


# -- regulation laws against direct computations ------------------------------------------------
def test_regulation_laws():
    assert scaled_lookahead(0.4, 1.5, 0.3, 0.9) == pytest.approx(0.6)
    assert scaled_lookahead(0.0, 1.5, 0.3, 0.9) == 0.3
    assert scaled_lookahead(-2.0, 1.5, 0.3, 0.9) == 0.9
    # radius 0.45 < min radius 0.9: v·(1 − |0.45 − 0.9|/0.9) = v/2
    assert curvature_limited_speed(0.5, 1.0 / 0.45, 0.9) == pytest.approx(0.25)
    assert curvature_limited_speed(0.5, 1.0 / 2.0, 0.9) == 0.5
    assert curvature_limited_speed(0.5, 0.0, 0.9) == 0.5
    assert obstacle_limited_speed(0.5, 0.15, 0.3, 1.0) == pytest.approx(0.25)
    assert obstacle_limited_speed(0.5, 0.5, 0.3, 1.0) == 0.5
    assert obstacle_limited_speed(0.5, -0.1, 0.3, 1.0) == 0.0
    assert approach_limited_speed(0.5, 0.5, 0.4, 1.0, 0.05) == pytest.approx(0.2)
    assert approach_limited_speed(0.5, 0.5, 0.01, 1.0, 0.05) == pytest.approx(0.05)
    assert approach_limited_speed(0.02, 0.5, 0.01, 1.0, 0.05) == 0.02  # never raises
    assert approach_limited_speed(0.5, 2.0, 0.4, 1.0, 0.05) == 0.5
    # Ramp from rest: accel·dt; near the heading: √(2·decel·angle).
    assert rotation_speed(1.0, 0.0, 0.1, 1.8, 3.2, 3.2, 2.5) == pytest.approx(0.32)
    assert rotation_speed(-1.0, -1.8, 0.1, 1.8, 3.2, 3.2, 2.5) == pytest.approx(-1.8)
    assert rotation_speed(0.01, 1.0, 0.1, 1.8, 3.2, 3.2, 2.5) == pytest.approx(
        max(math.sqrt(2 * 3.2 * 0.01), 1.0 - 0.32))


def test_dynamic_window_selection():
    window = velocity_window((0.2, 0.0), 0.1, (-0.5, 0.5, 1.0, 1.0), (-1.0, 1.0, 2.0, 2.0))
    assert window == pytest.approx((0.1, 0.3, -0.2, 0.2))
    # The line ω = 0.5·v crosses the window: the speed nearest the target on it.
    assert select_command(0.5, 0.5, window) == pytest.approx((0.3, 0.15))
    # ω = 5·v leaves the window above v = 0.04: the largest v that keeps ω ≤ 0.2.
    assert select_command(0.5, 5.0, window) == pytest.approx((0.1, 0.2))
    # ω = 20·v misses it: the corner nearest to the line.
    assert select_command(0.5, 20.0, window) == pytest.approx((0.1, 0.2))


def test_path_geometry():
    path = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 0.0], [0.5, 0.0]])
    assert list(cusp_indices(path)) == [2]
    seg, t, point = project_on_path(path, np.array([1.5, 0.3]), 0, 2)
    assert seg == 1 and t == pytest.approx(0.5) and point == pytest.approx([1.5, 0.0])
    carrot = carrot_point(path, np.array([0.0, 0.0]), 1, 2, 0.6, first_point=np.zeros(2))
    assert carrot == pytest.approx([0.6, 0.0])
    assert carrot_point(path, np.array([1.8, 0.0]), 2, 2, 0.6) == pytest.approx([2.0, 0.0])
    extended = carrot_point(path[:3], np.array([1.8, 0.0]), 2, 2, 0.6, extend_after_end=True)
    assert extended == pytest.approx([2.4, 0.0])


def test_corridor_clearance_from_lethal_cells():
    costmap = Costmap2D.filled(100, 100, 0.05, -2.5, -2.5)
    ix, iy = costmap.world_to_cell(0.8, 0.1)
    costmap.data[iy, ix] = LETHAL_OBSTACLE
    cx, cy = costmap.cell_to_world(ix, iy)
    clearance = corridor_clearance(costmap, (0.0, 0.0, 0.0), 1.0, 0.45, 0.35)
    assert clearance == pytest.approx(math.hypot(cx, cy) - 0.35)
    assert corridor_clearance(costmap, (0.0, 0.0, math.pi), 1.0, 0.45, 0.35) == math.inf
    assert corridor_clearance(costmap, (0.0, 0.0, math.pi), 1.0, 0.45, 0.35, reverse=True) == (
        pytest.approx(math.hypot(cx, cy) - 0.35))
    costmap.data[iy, ix] = 255  # unknown is not an obstacle
    assert corridor_clearance(costmap, (0.0, 0.0, 0.0), 1.0, 0.45, 0.35) == math.inf


# -- closed loop ---------------------------------------------------------------------------------
@pytest.mark.parametrize("make_path", [straight_path, arc_path])
def test_follows_a_path_within_tolerance_and_stops_at_the_goal(make_path):
    controller = make_controller()
    path = make_path()
    poses, commands, states = run_closed_loop(controller, path, (0.0, 0.05, 0.0))
    assert states[-1] == ARRIVED
    assert commands[-1] == pytest.approx((0.0, 0.0))
    goal = path[-1]
    assert math.hypot(poses[-1][0] - goal[0], poses[-1][1] - goal[1]) <= 0.25
    assert abs(normalize_angle(poses[-1][2] - goal[2])) <= 0.25
    deviation = max(distance_to_polyline(path[:, :2], p[:2]) for p in poses)
    assert deviation < 0.1
    assert_within_limits(commands)
    assert commands[:, 0].max() == pytest.approx(LIMITS.max_linear_vel)


def test_tighter_goal_tolerance_from_nav_state():
    controller = make_controller()
    nav_state = NavState()
    nav_state.set("goal_tolerance.position", 0.05)
    nav_state.set("goal_tolerance.yaw", 0.05)
    path = straight_path(2.0)
    poses, _commands, states = run_closed_loop(controller, path, (0.0, 0.0, 0.0),
                                               nav_state=nav_state)
    assert states[-1] == ARRIVED
    assert math.hypot(poses[-1][0] - 2.0, poses[-1][1]) <= 0.05


def test_slows_in_a_sharp_curve_as_the_parameters_say():
    algorithm = RegulatedPurePursuit()
    params = dict(make_controller().params)
    # A circle of radius 0.45 (half the min radius): pure pursuit's curvature is 1/0.45.
    radius = 0.45
    a = np.linspace(0.0, math.pi, 200)
    path = np.column_stack((radius * np.sin(a), radius * (1.0 - np.cos(a)), a))
    command = algorithm.compute((0.0, 0.0, 0.0), path, 0.05, LIMITS, params, 0.25, 0.25)
    assert command.state == FOLLOWING
    expected = 0.5 * (1.0 - abs(radius - 0.9) / 0.9)
    assert command.regulations["curvature"] == pytest.approx(expected, rel=0.03)
    assert command.v == pytest.approx(max(expected, 0.25), rel=0.03)
    assert command.w == pytest.approx(command.v / radius, rel=0.03)
    # Straight: nominal speed.
    command = RegulatedPurePursuit().compute((0.0, 0.0, 0.0), straight_path(), 0.05, LIMITS,
                                             params, 0.25, 0.25)
    assert command.v == pytest.approx(0.5)


def test_slows_near_obstacles_as_the_parameters_say():
    params = dict(make_controller({"use_obstacle_regulated_linear_velocity_scaling": True,
                                   "obstacle_scaling_dist": 0.6,
                                   "regulated_linear_scaling_min_speed": 0.05}).params)
    costmap = Costmap2D.filled(200, 100, 0.05, -1.0, -2.5)
    ix, iy = costmap.world_to_cell(0.55, 0.02)
    costmap.data[iy, ix] = LETHAL_OBSTACLE
    ox, oy = costmap.cell_to_world(ix, iy)
    radius = 0.3
    command = RegulatedPurePursuit().compute((0.0, 0.0, 0.0), straight_path(), 0.05, LIMITS,
                                             params, 0.25, 0.25, costmap, radius)
    clearance = math.hypot(ox, oy) - radius
    assert command.regulations["clearance"] == pytest.approx(clearance)
    assert command.v == pytest.approx(0.5 * clearance / 0.6)
    # Without the costmap: no obstacle term.
    command = RegulatedPurePursuit().compute((0.0, 0.0, 0.0), straight_path(), 0.05, LIMITS,
                                             params, 0.25, 0.25, None, radius)
    assert command.v == pytest.approx(0.5)


def test_slows_for_the_walls_of_an_occupancy_grid_map():
    # The simple maps manager writes a SimpleMap (boolean cells) in `map`: its walls slow the
    # robot as a costmap's lethal cells do (before, they were no obstacles at all).
    from test_map_as_costmap import OccupancyCells

    cells = np.zeros((50, 60), dtype=bool)
    cells[25, 12] = True  # the cell [0.2, 0.3) x [0.0, 0.1)
    nav_state = NavState()
    nav_state.set("map", OccupancyCells(cells, resolution=0.1, origin_x=-1.0, origin_y=-2.5))
    controller = make_controller({"use_obstacle_regulated_linear_velocity_scaling": True,
                                  "obstacle_scaling_dist": 0.6})
    run_closed_loop(controller, straight_path(3.0), (0.0, 0.0, 0.0), steps=1,
                    nav_state=nav_state)
    radius = controller.get_robot_geometry().radius
    clearance = controller.last_command.regulations["clearance"]
    assert clearance == pytest.approx(math.hypot(0.25, 0.05) - radius)


def test_rotates_to_heading_with_hysteresis():
    controller = make_controller()
    path = straight_path(3.0)
    nav_state = NavState()
    nav_state.set("path", Path.from_xy_yaw(path))
    angles = []

    def record(ctrl, pose, _cmd):
        angles.append((ctrl.state, pose[2]))

    poses, commands, states = run_closed_loop(controller, path, (0.0, 0.0, 2.0),
                                              on_step=record)
    assert states[0] == ROTATING_TO_HEADING and commands[0][0] == 0.0
    rotating = [yaw for state, yaw in angles if state == ROTATING_TO_HEADING]
    # Starts above 0.785 rad and keeps rotating below it (down to about half of it).
    assert min(abs(y) for y in rotating) < 0.785
    first_following = next(i for i, s in enumerate(states) if s == FOLLOWING)
    assert abs(poses[first_following][2]) < 0.785 / 2 + 0.1
    assert states[-1] == ARRIVED
    assert_within_limits(commands)


def test_reversing_through_a_cusp():
    forward = np.column_stack((np.arange(0.0, 2.0 + 1e-9, 0.05), np.zeros(41), np.zeros(41)))
    back_x = np.arange(1.95, 0.8 - 1e-9, -0.05)
    # Reverse along a gentle arc to the left, keeping the forward heading (Reeds–Shepp style).
    back = np.column_stack((back_x, 0.25 * (2.0 - back_x) ** 2, np.zeros_like(back_x)))
    path = np.vstack((forward, back))
    controller = make_controller({"allow_reversing": True})
    poses, commands, states = run_closed_loop(controller, path, (0.0, 0.0, 0.0))
    assert states[-1] == ARRIVED
    assert commands[:, 0].min() < -0.05 and commands[:, 0].max() > 0.3
    assert max(p[0] for p in poses) > 1.85  # reached the cusp before reversing
    assert math.hypot(poses[-1][0] - path[-1][0], poses[-1][1] - path[-1][1]) <= 0.25
    deviation = max(distance_to_polyline(path[:, :2], p[:2]) for p in poses)
    assert deviation < 0.12
    assert_within_limits(commands)


def test_dynamic_window_keeps_acceleration_limits():
    controller = make_controller({"use_dynamic_window": True})
    poses, commands, states = run_closed_loop(controller, arc_path(), (0.0, 0.0, 0.0))
    assert states[-1] == ARRIVED
    following = [i for i, s in enumerate(states) if s == FOLLOWING]
    dv = np.diff(commands[following[0]:following[-1] + 1, 0])
    assert dv.max() <= LIMITS.max_linear_acc * 0.05 + 1e-9
    assert dv.min() >= -LIMITS.max_linear_decel * 0.05 - 1e-9
    assert_within_limits(commands)


def test_limits_in_force_are_read_every_cycle_and_deprecated_caps_apply():
    controller = make_controller({"max_linear_vel": 0.4})
    nav_state = NavState()
    nav_state.set("path", Path.from_xy_yaw(straight_path()))
    set_pose(nav_state, 0.0, 0.0, 0.0)
    controller.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.vx == pytest.approx(0.4)
    controller.limits_holder["limits"] = RobotLimits(max_linear_vel=0.2)  # a slow-down
    controller.context.now.t += 0.05
    controller.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.vx == pytest.approx(0.2)


def test_zero_command_when_idle_without_path_or_pose():
    controller = make_controller()
    nav_state = NavState()
    controller.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()
    nav_state.set("path", Path.from_xy_yaw(straight_path()))
    set_pose(nav_state, 0.0, 0.0, 0.0)
    nav_state.set("navigation_state", "IDLE")
    controller.context.now.t += 0.05
    controller.update_rt(nav_state)
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()


def test_bad_parameter_is_named():
    with pytest.raises(PluginConfigurationError, match="rpp.lookahead_dist"):
        make_controller({"lookahead_dist": -1.0})
    with pytest.raises(PluginConfigurationError, match="rpp.use_dynamic_window"):
        make_controller({"use_dynamic_window": "yes"})


def test_a_section_of_the_original_loads_unchanged():
    # Every parameter of the original EasyNav's RPP (easynav_regulated_pp_controller, a port of
    # Nav2's that is not parameter-compatible with it) with its default.
    original = {
        "lookahead_dist": 0.6, "min_lookahead_dist": 0.3, "max_lookahead_dist": 0.9,
        "lookahead_time": 1.5, "use_velocity_scaled_lookahead_dist": False,
        "max_linear_vel": 0.5, "min_linear_vel": -0.5, "max_angular_vel": 2.5,
        "min_angular_vel": -2.5, "max_linear_accel": 2.5, "max_linear_decel": 2.5,
        "max_angular_accel": 3.2, "max_angular_decel": 3.2, "use_dynamic_window": False,
        "allow_reversing": False, "use_rotate_to_heading": True,
        "rotate_to_heading_angular_vel": 1.8, "rotate_to_heading_min_angle": 0.785,
        "use_regulated_linear_velocity_scaling": True,
        "regulated_linear_scaling_min_radius": 0.9, "regulated_linear_scaling_min_speed": 0.25,
        "use_fixed_curvature_lookahead": False, "curvature_lookahead_dist": 1.0,
        "interpolate_curvature_after_goal": False,
        "use_obstacle_regulated_linear_velocity_scaling": False, "obstacle_scaling_dist": 0.3,
        "obstacle_scaling_gain": 1.0, "min_approach_linear_velocity": 0.05,
        "approach_velocity_scaling_dist": 1.0, "xy_goal_tolerance": 0.25,
        "yaw_goal_tolerance": 0.25,
    }
    declared = {p.name for p in RegulatedPurePursuitController.parameter_declarations()}
    assert set(original) <= declared
    controller = make_controller(original, limits=RobotLimits(max_linear_vel=1.0,
                                                              max_angular_vel=3.0))
    # The original's limits cap the limits in force (never raise them).
    limits = controller.limits()
    assert limits.max_linear_vel == 0.5 and limits.max_angular_vel == 2.5
    assert limits.min_linear_vel == RobotLimits().min_linear_vel  # -0.2 is tighter than -0.5


def test_a_rotation_toward_a_target_behind_keeps_its_direction():
    from easynav.controllers.regulated_pp.regulation import latched_angle

    assert latched_angle(-3.1, 1.0) == pytest.approx(3.1)  # noise flipped it: keep turning left
    assert latched_angle(-1.0, 1.0) == -1.0  # not ambiguous: the real sign
    assert latched_angle(-3.1, 0.0) == -3.1
    # Closed loop: the path starts straight behind the robot, the pose estimate jitters across
    # ±π; the robot turns round one way and follows the path.
    controller = make_controller()
    path = straight_path(2.0)
    path[:, 0] *= -1.0
    path[:, 2] = math.pi
    jitter = itertools.cycle((0.03, -0.03))
    nav_state = NavState()
    nav_state.set("path", Path.from_xy_yaw(path))
    x, y, yaw = 0.0, 0.0, 0.0
    for _ in range(600):
        set_pose(nav_state, x, y, normalize_angle(yaw + next(jitter)))
        controller.update_rt(nav_state)
        cmd = nav_state.get("cmd_vel", TwistStamped).twist
        if controller.state == ARRIVED:
            break
        x += cmd.vx * math.cos(yaw) * 0.05
        y += cmd.vx * math.sin(yaw) * 0.05
        yaw = normalize_angle(yaw + cmd.wz * 0.05)
        controller.context.now.t += 0.05
    assert controller.state == ARRIVED and x < -1.7
