"""Kinematics, limits, odometry noise, the scanner, moving obstacles and collisions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.playground.sim import (
    BaseLimits,
    DiffDriveRobot,
    LaserScanner,
    MovingObstacle,
    Simulation,
    WheelOdometry,
    World,
)


def empty_world(size=10.0, res=0.05):
    n = round(size / res)
    return World(np.zeros((n, n), dtype=bool), res, -size / 2, -size / 2, name="empty")


def boxed_world(size=6.0, res=0.05):
    n = round(size / res)
    grid = np.zeros((n, n), dtype=bool)
    grid[:2, :] = grid[-2:, :] = grid[:, :2] = grid[:, -2:] = True
    return World(grid, res, -size / 2, -size / 2, name="box")


def make_sim(world, robot=None, obstacles=(), noise=0.0, seed=1):
    rng = np.random.default_rng(seed)
    return Simulation(
        world,
        robot or DiffDriveRobot(),
        LaserScanner(range_noise_std=noise, rng=rng),
        WheelOdometry(1.0, 1.0, 0.0, 0.0, 0.0, rng=rng),
        obstacles=obstacles,
        robot_radius=0.2,
        step=0.005,
    )


def test_constant_command_drives_a_circle_of_radius_v_over_w():
    robot = DiffDriveRobot(limits=BaseLimits(max_linear_acc=1e6, max_angular_acc=1e6))
    robot.set_command(0.5, 0.5, now=0.0)
    steps = round(2 * math.pi / 0.5 / 0.005)  # one full turn
    xs, ys = [], []
    for k in range(steps):
        robot.step(0.005, now=k * 0.005)
        xs.append(robot.x)
        ys.append(robot.y)
    # Centre of the circle is (0, 1) for a start at the origin heading +x.
    radii = np.hypot(np.array(xs), np.array(ys) - 1.0)
    assert np.allclose(radii, 1.0, atol=1e-6)
    assert math.hypot(robot.x, robot.y) < 1e-3  # back at the start after a full turn


def test_velocity_ramps_within_acceleration_and_clamps_to_the_base_maximum():
    limits = BaseLimits(max_linear_vel=0.7, max_linear_acc=1.0, max_linear_decel=2.0)
    robot = DiffDriveRobot(limits=limits)
    robot.set_command(5.0, 0.0, now=0.0)  # far beyond the base: clamped
    assert robot.command == (0.7, 0.0)
    robot.step(0.1, now=0.0)
    assert robot.v == pytest.approx(0.1)
    for k in range(20):
        robot.step(0.1, now=0.1 * k)
    assert robot.v == pytest.approx(0.7)
    robot.set_command(-0.3, 0.0, now=2.0)
    robot.step(0.1, now=2.0)
    assert robot.v == pytest.approx(0.5)  # braking at 2 m/s^2
    for k in range(3):
        robot.step(0.1, now=2.1 + 0.1 * k)
    # 0.5 -> 0 takes 0.25 s at 2 m/s^2; then 0.05 s of reverse acceleration at 1 m/s^2.
    assert robot.v == pytest.approx(-0.05)


def test_last_command_is_kept_unless_a_timeout_is_configured():
    keep = DiffDriveRobot(limits=BaseLimits(max_linear_acc=1e6, max_linear_decel=1e6))
    guarded = DiffDriveRobot(
        limits=BaseLimits(max_linear_acc=1e6, max_linear_decel=1e6), cmd_timeout=0.5
    )
    for robot in (keep, guarded):
        robot.set_command(0.3, 0.0, now=0.0)
        for k in range(200):  # 2 s without a new command
            robot.step(0.01, now=k * 0.01)
    assert keep.v == pytest.approx(0.3)
    assert guarded.v == 0.0
    assert guarded.x == pytest.approx(0.3 * 0.51, abs=0.01)


def test_non_finite_commands_are_refused():
    robot = DiffDriveRobot()
    with pytest.raises(ValueError, match="non-finite"):
        robot.set_command(math.nan, 0.0, now=0.0)
    sim = make_sim(empty_world())
    with pytest.raises(ValueError, match="non-finite"):
        sim.set_command(0.1, math.inf)


def test_odometry_scale_error_and_drift_statistics():
    # 200 robots drive 10 m straight: the mean error is the scale bias, the spread grows as
    # sqrt(distance) with the configured coefficient.
    finals = []
    for seed in range(200):
        odom = WheelOdometry(1.02, 1.0, 0.02, 0.0, 0.0, rng=np.random.default_rng(seed))
        for _ in range(1000):
            odom.update(0.01, 0.0, 0.01)
        finals.append(odom.x)
    finals = np.array(finals)
    assert finals.mean() == pytest.approx(10.2, abs=0.01)
    assert finals.std() == pytest.approx(0.02 * math.sqrt(10.0), rel=0.2)


def test_odometry_heading_drifts_with_distance():
    yaws = []
    for seed in range(200):
        odom = WheelOdometry(1.0, 1.0, 0.0, 0.0, 0.01, rng=np.random.default_rng(seed))
        for _ in range(400):
            odom.update(0.01, 0.0, 0.01)
        yaws.append(odom.yaw)
    assert np.std(yaws) == pytest.approx(0.01 * 2.0, rel=0.2)  # 4 m driven


def test_odometry_without_noise_follows_the_true_path():
    sim = make_sim(empty_world())
    sim.set_command(0.4, 0.3)
    sim.run_for(5.0)
    robot, odom = sim.robot, sim.odometry
    # Odometry starts at (0, 0, 0) where the robot started (also the origin here).
    assert odom.x == pytest.approx(robot.x, abs=1e-3)
    assert odom.y == pytest.approx(robot.y, abs=1e-3)
    assert odom.yaw == pytest.approx(robot.yaw, abs=1e-6)


def test_scanner_geometry_and_inf_for_no_return():
    scanner = LaserScanner(beams=360, range_noise_std=0.0, max_range=3.0)
    assert scanner.angle_min == pytest.approx(-math.pi)
    assert scanner.angle_increment == pytest.approx(math.radians(1.0))
    ranges = scanner.scan(empty_world(), 0.0, 0.0, 0.0)
    assert np.all(np.isposinf(ranges))
    partial = LaserScanner(beams=5, fov=math.pi)
    assert partial.angles.tolist() == pytest.approx(
        [-math.pi / 2, -math.pi / 4, 0, math.pi / 4, math.pi / 2]
    )


def test_scanner_noise_has_the_configured_spread_and_too_close_is_minus_inf():
    world = boxed_world()  # inner wall faces at +-2.9 m
    scanner = LaserScanner(beams=360, range_noise_std=0.02, rng=np.random.default_rng(3))
    ranges = np.concatenate([scanner.scan(world, 0.0, 0.0, 0.0) for _ in range(20)])
    exact = LaserScanner(beams=360, range_noise_std=0.0).scan(world, 0.0, 0.0, 0.0)
    errors = ranges - np.tile(exact, 20)
    assert np.std(errors) == pytest.approx(0.02, rel=0.1)
    assert abs(np.mean(errors)) < 0.003
    close = LaserScanner(min_range=0.5, range_noise_std=0.0).scan(world, 2.7, 0.0, 0.0)
    assert close[180] == -np.inf  # the wall 0.2 m ahead is inside the minimum range


def test_moving_obstacle_walks_back_and_forth_and_is_seen_by_the_scanner():
    person = MovingObstacle([(1.0, 0.0), (1.0, 2.0)], radius=0.25, speed=0.5, name="person")
    scanner = LaserScanner(beams=360, range_noise_std=0.0, max_range=5.0)
    world = empty_world()
    ahead = 180  # beam at angle 0
    ranges = scanner.scan(world, 0.0, 0.0, 0.0, [person])
    assert ranges[ahead] == pytest.approx(0.75)
    person.advance(2.0)  # 1 m along the track: at (1, 1), out of the beam
    assert person.position == pytest.approx((1.0, 1.0))
    assert np.isposinf(scanner.scan(world, 0.0, 0.0, 0.0, [person])[ahead])
    person.advance(4.0)  # to the end (1, 2) and back 1 m: (1, 1) again
    assert person.position == pytest.approx((1.0, 1.0))
    person.advance(2.0)
    assert person.position == pytest.approx((1.0, 0.0))


def test_driving_into_a_wall_stops_the_robot_and_records_one_collision():
    sim = make_sim(boxed_world())
    events = []
    sim.on_collision.append(events.append)
    sim.set_command(0.5, 0.0)
    sim.run_for(10.0)
    # Inner face at x = 2.9, robot radius 0.2: it stops just before 2.7.
    assert 2.69 < sim.robot.x <= 2.7
    assert sim.robot.v == 0.0
    assert len(events) == 1 and events[0].with_what == "wall"
    assert sim.recorder.collisions[0]["x"] == pytest.approx(sim.robot.x, abs=0.005)
    # Backing off and hitting again is a second collision.
    sim.set_command(-0.3, 0.0)
    sim.run_for(1.0)
    sim.set_command(0.5, 0.0)
    sim.run_for(4.0)
    assert len(events) == 2


def test_obstacle_waits_instead_of_walking_into_a_stopped_robot():
    person = MovingObstacle([(2.0, 0.0), (-2.0, 0.0)], radius=0.25, speed=0.5, name="person")
    sim = make_sim(empty_world(), obstacles=[person])
    sim.run_for(8.0)
    assert sim.recorder.collisions == []
    assert person.position[0] == pytest.approx(0.45, abs=0.01)  # waiting at the robot's edge


def test_robot_driving_into_an_obstacle_collides_with_it():
    person = MovingObstacle([(1.5, 0.0), (1.5, 0.01)], radius=0.25, speed=0.0, name="person")
    sim = make_sim(empty_world(), obstacles=[person])
    sim.set_command(0.5, 0.0)
    sim.run_for(5.0)
    assert [c["with"] for c in sim.recorder.collisions] == ["person"]
    assert sim.recorder.min_clearance <= 0.005


def test_start_pose_in_a_wall_is_refused_naming_the_pose():
    with pytest.raises(ValueError, match=r"start pose \(2\.900, 0\.000\)"):
        make_sim(boxed_world(), robot=DiffDriveRobot(2.9, 0.0))


def test_sensor_callbacks_run_at_their_rates_in_simulated_time():
    sim = make_sim(empty_world())
    scans, odoms = [], []
    sim.on_scan.append(lambda stamp, ranges: scans.append(stamp))
    sim.on_odometry.append(odoms.append)
    sim.run_for(2.0)
    assert len(scans) == 20 and len(odoms) == 100
    assert np.allclose(np.diff(scans), 0.1) and np.allclose(np.diff(odoms), 0.02)


def test_recorder_tracks_distance_clearance_and_localisation_error():
    sim = make_sim(boxed_world())
    sim.set_command(0.5, 0.0)
    sim.run_for(2.0)
    rec = sim.recorder
    assert rec.distance_driven() == pytest.approx(sim.robot.x, abs=0.01)
    # Closest approach to the east wall (inner face 2.9) minus the robot radius.
    assert rec.min_clearance == pytest.approx(2.9 - sim.robot.x - 0.2, abs=0.011)
    for stamp, x, y, _ in rec.true_poses[::10]:
        rec.record_estimate(stamp, x + 0.1, y, 0.0)
    assert np.allclose(rec.localisation_errors(), 0.1)


def test_a_teleported_robot_is_moved_without_odometry_and_not_into_a_wall():
    """A kidnapped robot: the true pose jumps, the wheel odometry sees nothing of it."""
    sim = make_sim(boxed_world())
    sim.set_command(0.3, 0.0)
    sim.run_for(1.0)
    odom_before = (sim.odometry.x, sim.odometry.y, sim.odometry.yaw)
    sim.teleport(-1.5, 1.0, math.pi / 2)
    sim.step()
    # Carried there stopped (the step then ramps it up again towards the command in force).
    assert (sim.robot.x, sim.robot.y, sim.robot.yaw) == pytest.approx((-1.5, 1.0, math.pi / 2),
                                                                      abs=1e-3)
    assert sim.robot.v < 0.01
    assert (sim.odometry.x, sim.odometry.y, sim.odometry.yaw) == pytest.approx(odom_before,
                                                                               abs=1e-3)
    sim.teleport(2.85, 0.0, 0.0)  # into the wall (inner face at 2.9, radius 0.2): refused
    sim.step()
    assert sim.robot.x < 0.0
    assert [e[-1] for e in sim.teleport_events] == [True, False]
    with pytest.raises(ValueError, match="not finite"):
        sim.teleport(math.nan, 0.0, 0.0)
