"""Several robots in one world (Fleet): each sees the others, collisions between robots."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.playground.sim import (
    BaseLimits,
    DiffDriveRobot,
    Fleet,
    LaserScanner,
    MovingObstacle,
    Simulation,
    WheelOdometry,
    World,
)

FAST = BaseLimits(max_linear_acc=1e6, max_angular_acc=1e6, max_linear_decel=1e6,
                  max_angular_decel=1e6)


def empty_world(size=10.0, res=0.05):
    n = round(size / res)
    return World(np.zeros((n, n), dtype=bool), res, -size / 2, -size / 2, name="empty")


def make_sim(world, x, y, yaw, radius=0.2, obstacles=(), noise=0.0, seed=1, step=0.005):
    rng = np.random.default_rng(seed)
    return Simulation(
        world,
        DiffDriveRobot(x, y, yaw, limits=FAST),
        LaserScanner(range_noise_std=noise, rng=rng),
        WheelOdometry(1.0, 1.0, 0.0, 0.0, 0.0, rng=rng),
        obstacles=obstacles,
        robot_radius=radius,
        step=step,
    )


def beam_towards(scanner: LaserScanner, angle: float) -> int:
    return int(np.argmin(np.abs((scanner.angles - angle + math.pi) % (2 * math.pi) - math.pi)))


def test_each_robot_sees_the_other_as_a_disc_of_its_radius():
    world = empty_world()
    a = make_sim(world, 0.0, 0.0, 0.0, radius=0.2)
    b = make_sim(world, 2.0, 0.0, math.pi / 2, radius=0.3)
    Fleet([a, b], ["r1", "r2"])
    # a's laser is 0.1 m ahead of its centre: b's disc (radius 0.3) is 2.0 - 0.1 - 0.3 away.
    assert a.scan_now()[beam_towards(a.scanner, 0.0)] == pytest.approx(1.6, abs=1e-9)
    # b faces +y, its laser at (2.0, 0.1); its beam at +pi/2 points along -x, 0.1 m off a's
    # centre: it enters a's disc (radius 0.2) at x = sqrt(0.2^2 - 0.1^2).
    expected = 2.0 - math.sqrt(0.2**2 - 0.1**2)
    assert b.scan_now()[beam_towards(b.scanner, math.pi / 2)] == pytest.approx(expected, abs=1e-9)
    # Nothing else in the empty world.
    assert np.isinf(a.scan_now()[beam_towards(a.scanner, math.pi)])


def test_a_robot_alone_in_a_fleet_steps_exactly_like_its_simulation():
    world = empty_world()
    obstacles = [MovingObstacle([[1.0, 1.5], [1.0, -1.5]], radius=0.2, speed=0.5, name="p")]
    alone = make_sim(world, 0.0, 0.0, 0.0, obstacles=obstacles, noise=0.01)
    obstacles2 = [MovingObstacle([[1.0, 1.5], [1.0, -1.5]], radius=0.2, speed=0.5, name="p")]
    fleet_sim = make_sim(world, 0.0, 0.0, 0.0, noise=0.01)
    fleet = Fleet([fleet_sim], ["r1"], obstacles=obstacles2)
    scans_alone, scans_fleet = [], []
    alone.on_scan.append(lambda t, r: scans_alone.append((t, r.copy())))
    fleet_sim.on_scan.append(lambda t, r: scans_fleet.append((t, r.copy())))
    for sim in (alone, fleet_sim):
        sim.set_command(0.4, 0.3)
    alone.run_for(6.0)
    fleet.run_for(6.0)
    assert fleet.time == alone.time
    assert alone.recorder.to_dict() == fleet_sim.recorder.to_dict()
    assert len(scans_alone) == len(scans_fleet) == 60
    for (ta, ra), (tb, rb) in zip(scans_alone, scans_fleet, strict=True):
        assert ta == tb
        np.testing.assert_array_equal(ra, rb)
    assert obstacles[0].position == obstacles2[0].position


def test_robots_driving_at_each_other_stop_and_record_the_collision_with_names():
    world = empty_world()
    a = make_sim(world, -1.0, 0.0, 0.0)
    b = make_sim(world, 1.0, 0.0, math.pi)
    fleet = Fleet([a, b], ["r1", "r2"])
    a.set_command(0.5, 0.0)
    b.set_command(0.5, 0.0)
    fleet.run_for(4.0)
    gap = a.robot.x - b.robot.x
    assert -0.41 < gap < -0.39  # touching (radii 0.2 + 0.2), not overlapping
    assert [c.with_what for c in a.checker.collisions] == ["r2"]
    assert [c.with_what for c in b.checker.collisions] == ["r1"]
    assert [c["with"] for c in a.recorder.collisions] == ["r2"]
    # Both stopped where they touched; the odometry saw no motion while blocked.
    assert a.robot.v == 0.0 and b.robot.v == 0.0
    assert a.odometry.x == pytest.approx(a.robot.x + 1.0, abs=1e-9)


def test_robots_passing_each_other_at_a_distance_do_not_collide():
    world = empty_world()
    a = make_sim(world, -2.0, 0.3, 0.0)
    b = make_sim(world, 2.0, -0.3, math.pi)
    fleet = Fleet([a, b], ["r1", "r2"])
    a.set_command(0.5, 0.0)
    b.set_command(0.5, 0.0)
    fleet.run_for(6.0)
    assert a.robot.x > 0.9 and b.robot.x < -0.9
    assert a.checker.collisions == [] and b.checker.collisions == []
    # The clearance record saw the other robot: 0.6 m between centres, 0.2 m between discs.
    assert a.recorder.min_clearance == pytest.approx(0.2, abs=0.02)


def test_moving_obstacles_are_shared_and_wait_for_every_robot():
    world = empty_world()
    person = MovingObstacle([[0.0, 1.0], [0.0, -3.0]], radius=0.2, speed=0.5, name="person")
    a = make_sim(world, -3.0, 0.0, 0.0)
    b = make_sim(world, 0.0, -1.0, 0.0)  # stands on the person's path
    fleet = Fleet([a, b], ["r1", "r2"], obstacles=[person])
    assert a.obstacles is b.obstacles is fleet.obstacles
    fleet.run_for(4.0)
    # It walked down and waits in front of r2 (never walked into it), seen by r1's laser.
    assert person.position[1] == pytest.approx(-0.6, abs=0.01)
    assert b.checker.collisions == []
    r1_beam = a.scan_now()[beam_towards(a.scanner, math.atan2(-0.6, 2.9))]
    assert r1_beam < 3.2


def test_teleport_into_another_robot_is_refused():
    world = empty_world()
    a = make_sim(world, 0.0, 0.0, 0.0)
    b = make_sim(world, 2.0, 0.0, 0.0)
    fleet = Fleet([a, b], ["r1", "r2"])
    a.teleport(1.8, 0.0, 0.0)
    fleet.step()
    assert a.teleport_events[-1][-1] is False
    assert (a.robot.x, a.robot.y) == (0.0, 0.0)


def test_bad_fleets_are_refused_by_name():
    world = empty_world()
    with pytest.raises(ValueError, match="robot 'r1' overlaps r2"):
        Fleet([make_sim(world, 0.0, 0.0, 0.0), make_sim(world, 0.3, 0.0, 0.0)], ["r1", "r2"])
    with pytest.raises(ValueError, match="unique name"):
        Fleet([make_sim(world, 0.0, 0.0, 0.0), make_sim(world, 2.0, 0.0, 0.0)], ["r1", "r1"])
    with pytest.raises(ValueError, match="one step"):
        Fleet([make_sim(world, 0.0, 0.0, 0.0), make_sim(world, 2.0, 0.0, 0.0, step=0.01)],
              ["r1", "r2"])
    with pytest.raises(ValueError, match="another world"):
        Fleet([make_sim(world, 0.0, 0.0, 0.0), make_sim(empty_world(), 2.0, 0.0, 0.0)],
              ["r1", "r2"])
    obstacle = MovingObstacle([[3.0, 3.0], [3.0, 4.0]])
    with pytest.raises(ValueError, match="of its own"):
        Fleet([make_sim(world, 0.0, 0.0, 0.0, obstacles=[obstacle])], ["r1"])
    fleet = Fleet([make_sim(world, 0.0, 0.0, 0.0)], ["r1"])
    with pytest.raises(KeyError, match="r9"):
        fleet.simulation("r9")
