"""Scenario hooks of the playground: a robot held in place, scripted obstacles."""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest

from easynav.playground.sim import (
    DiffDriveRobot,
    LaserScanner,
    MovingObstacle,
    ScriptedObstacle,
    Simulation,
    WheelOdometry,
    World,
)
from easynav.playground.world_description import WORLDS_DIR, WorldDescription


def empty_world(size=10.0, res=0.05):
    n = round(size / res)
    return World(np.zeros((n, n), dtype=bool), res, -size / 2, -size / 2, name="empty")


def make_sim(robot=None, obstacles=()):
    rng = np.random.default_rng(1)
    return Simulation(
        empty_world(),
        robot or DiffDriveRobot(),
        LaserScanner(range_noise_std=0.0, rng=rng),
        WheelOdometry(1.0, 1.0, 0.0, 0.0, 0.0, rng=rng),
        obstacles=obstacles,
        robot_radius=0.2,
        step=0.005,
    )


# ---------------------------------------------------------------------- held in place
def test_a_held_robot_is_commanded_but_neither_moves_nor_counts_odometry():
    sim = make_sim()
    sim.set_held(True)
    sim.set_command(0.5, 0.3)
    sim.run_for(2.0)
    assert (sim.robot.x, sim.robot.y, sim.robot.yaw) == (0.0, 0.0, 0.0)
    assert (sim.robot.v, sim.robot.w) == (0.0, 0.0)
    assert sim.robot.command == (0.5, 0.3)  # the command is still there
    assert (sim.odometry.x, sim.odometry.y, sim.odometry.v) == (0.0, 0.0, 0.0)
    assert sim.recorder.collisions == []
    assert sim.recorder.distance_driven() == 0.0


def test_a_released_robot_drives_on_with_the_command_it_has():
    sim = make_sim()
    sim.set_command(0.4, 0.0)
    sim.set_held(True)
    sim.run_for(1.0)
    sim.set_held(False)
    sim.run_for(2.0)
    assert sim.robot.x > 0.5
    assert sim.odometry.x == pytest.approx(sim.robot.x, abs=1e-6)
    assert sim.hold_events == [(0.0, True), (pytest.approx(1.0), False)]


def test_every_command_the_robot_took_is_recorded_with_the_step_it_applied_to():
    sim = make_sim()
    sim.set_command(0.4, 0.1, received=12.5)
    sim.run_for(1.0)
    sim.set_command(100.0, 0.0)  # clamped to the base limits, as recorded
    sim.set_command(0.0, 0.0)  # only the latest pending command is taken
    sim.run_for(0.5)
    assert sim.command_events == [(0.0, 0.4, 0.1, 12.5), (pytest.approx(1.0), 0.0, 0.0, None)]
    sim.set_command(100.0, 0.0)
    sim.run_for(0.1)
    assert sim.command_events[-1][1] == sim.robot.limits.max_linear_vel


# ---------------------------------------------------------------------- scripted obstacles
def test_scripted_obstacle_steps_out_when_the_robot_comes_within_start_distance():
    person = ScriptedObstacle(
        [(2.0, 1.0), (2.0, 0.0)], radius=0.2, speed=0.5, name="crosser", start_distance=1.5
    )
    sim = make_sim(obstacles=[person])
    sim.run_for(3.0)  # the robot stands 2.24 m away: the person waits
    assert person.position == (2.0, 1.0) and person.started_at is None
    sim.set_command(0.5, 0.0)
    sim.run_for(2.0)
    assert person.started
    # The robot came within 1.5 m of (2, 1) when it had driven ~0.88 m (after the 1 s ramp).
    assert 3.5 < person.started_at < 5.0
    assert sim.checker.colliding_with(sim.robot.x, sim.robot.y, [person]) is None


def test_scripted_obstacle_walks_once_and_stays_at_its_last_waypoint():
    person = ScriptedObstacle([(2.0, 1.0), (2.0, 2.0)], speed=0.5, start_time=1.0)
    sim = make_sim(obstacles=[person])
    sim.run_for(0.9)
    assert person.position == (2.0, 1.0)
    sim.run_for(3.1)  # started at 1.0, walked 1 m by 3.0, then stays
    assert person.started_at == pytest.approx(1.0, abs=0.006)
    assert person.position == pytest.approx((2.0, 2.0))
    sim.run_for(3.0)
    assert person.position == pytest.approx((2.0, 2.0))


def test_scripted_obstacle_with_repeat_walks_back_and_forth():
    person = ScriptedObstacle([(2.0, 1.0), (2.0, 2.0)], speed=0.5, start_time=0.0, repeat=True)
    sim = make_sim(obstacles=[person])
    sim.run_for(3.0)  # 1.5 m: to the end and half-way back
    assert person.position == pytest.approx((2.0, 1.5), abs=0.01)


def test_scripted_obstacle_stands_pause_seconds_at_intermediate_waypoints():
    person = ScriptedObstacle([(2.0, 1.0), (2.0, 2.0), (3.0, 2.0)], speed=0.5, pause=2.0)
    sim = make_sim(obstacles=[person])
    sim.run_for(2.0)  # walked the first leg
    assert person.position == pytest.approx((2.0, 2.0))
    sim.run_for(1.9)  # still standing there
    assert person.position == pytest.approx((2.0, 2.0))
    sim.run_for(1.1)  # pause over at 4.0 s, then 1 s of walking
    assert person.position == pytest.approx((2.5, 2.0), abs=0.01)
    sim.run_for(5.0)  # no pause at the last waypoint: it stays there
    assert person.position == pytest.approx((3.0, 2.0))


def test_a_scripted_obstacle_still_waits_instead_of_walking_into_the_robot():
    person = ScriptedObstacle([(1.5, 0.0), (-1.5, 0.0)], radius=0.25, speed=0.5)
    sim = make_sim(obstacles=[person])
    sim.run_for(6.0)
    assert sim.recorder.collisions == []
    assert person.position[0] == pytest.approx(0.45, abs=0.01)


@pytest.mark.parametrize(
    "kwargs, culprit",
    [
        ({"start_time": -1.0}, "start_time"),
        ({"start_distance": 0.0}, "start_distance"),
        ({"pause": math.nan}, "pause"),
        ({"pause": 1.0, "repeat": True}, "pause is for a single walk"),
        ({"speed": 0.0}, "speed"),
    ],
)
def test_bad_script_values_are_refused_naming_them(kwargs, culprit):
    with pytest.raises(ValueError, match=culprit):
        ScriptedObstacle([(0.0, 0.0), (1.0, 0.0)], name="p", **kwargs)


def test_world_description_makes_scripted_obstacles_from_their_keys(tmp_path):
    path = tmp_path / "crossing.yaml"
    path.write_text(
        f"map: {WORLDS_DIR / 'home.map'}\n"
        "start_pose: [4.8, 3.4, 0.0]\n"
        "moving_obstacles:\n"
        "  - {name: walker, waypoints: [[5.0, 0.9], [6.4, 0.9]]}\n"
        "  - {name: crosser, speed: 0.8, start_distance: 2.0,\n"
        "     waypoints: [[7.2, 4.6], [7.2, 3.4]]}\n"
    )
    walker, crosser = WorldDescription.resolve(str(path)).make_obstacles()
    assert type(walker) is MovingObstacle
    assert isinstance(crosser, ScriptedObstacle)
    assert (crosser.start_distance, crosser.repeat, crosser.speed) == (2.0, False, 0.8)

    path.write_text(
        f"map: {WORLDS_DIR / 'home.map'}\n"
        "moving_obstacles:\n"
        "  - {name: crosser, repeat: sometimes, waypoints: [[7.2, 4.6], [7.2, 3.4]]}\n"
    )
    with pytest.raises(ValueError, match=r"moving_obstacles\[0\]\.repeat"):
        WorldDescription.resolve(str(path)).make_obstacles()


# ---------------------------------------------------------------------- over ROS
@pytest.mark.ros
def test_a_latched_hold_on_playground_hold_holds_the_robot_until_released(ros_bed, tmp_path):
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import Bool

    from easynav.playground.ros.playground_node import PlaygroundNode

    latched = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
    )
    probe = Node("hold_probe", context=ros_bed.context)
    hold_pub = probe.create_publisher(Bool, "/playground/hold", latched)
    hold_pub.publish(Bool(data=True))  # before the playground exists: latched
    ros_bed.add(probe)
    record = tmp_path / "truth.json"
    node = PlaygroundNode(
        context=ros_bed.context,
        parameter_overrides=[
            Parameter("speed_up", value=4.0),
            Parameter("record", value=str(record)),
        ],
    )
    ros_bed.add(node)
    node.start()
    try:
        assert _wait(lambda: node.sim.held)
        node.sim.set_command(0.3, 0.0)
        t0 = node.sim.time
        assert _wait(lambda: node.sim.time > t0 + 1.0)
        assert node.sim.robot.x == pytest.approx(5.6) and node.sim.odometry.x == 0.0
        hold_pub.publish(Bool(data=False))
        assert _wait(lambda: not node.sim.held)
        assert _wait(lambda: node.sim.robot.x > 5.7)
    finally:
        node.stop()
    data = json.loads(record.read_text())
    assert data["obstacles"] == [{"name": "person", "started_at": 0.0}]
    (held_at, held), (released_at, released) = data["holds"]
    assert (held, released) == (True, False) and 0.0 <= held_at < released_at


def _wait(predicate, timeout=10.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()
