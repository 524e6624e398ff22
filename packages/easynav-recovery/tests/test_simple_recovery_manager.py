"""SimpleRecoveryManager without ROS: the reflex brake, the cases by severity, deprecations."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from recovery_harness import (
    Robot,
    Sim,
    clear_goal,
    make_context,
    scan,
    set_cmd,
    set_goal,
    set_pose,
)

from easynav.common.tf import get_tf_buffer
from easynav.core.plugins import PluginConfigurationError, PluginServices
from easynav.core.robot import RobotGeometry
from easynav.core.types import (
    DiagnosticLevel,
    DiagnosticStatus,
    Header,
    Transform,
    TransformStamped,
    Twist,
)
from easynav.recovery.simple import SimpleMitigation, SimpleRecoveryManager


def simple(params=None, geometry=None, robot=None) -> Sim:
    return Sim(SimpleRecoveryManager, params or {}, geometry=geometry, robot=robot)


# ── RT: braking before an obstacle ahead ─────────────────────────────────────────────────────
@pytest.mark.parametrize(
    ("point", "brakes"),
    [
        ((0.55, 0.0, 0.2), True),  # within radius 0.3 + stop_distance 0.3
        ((0.65, 0.0, 0.2), False),  # beyond it
        ((0.4, 0.25, 0.2), True),  # ahead, within the robot's width
        ((0.4, 0.35, 0.2), False),  # beside the robot's path
        ((0.4, 0.0, 0.03), False),  # the ground (z <= min_obstacle_z 0.05)
        ((0.4, 0.0, 0.6), False),  # above the robot (z >= robot_geometry.height 0.5)
        ((-0.4, 0.0, 0.2), False),  # behind
    ],
)
def test_brakes_only_for_a_point_in_the_box_ahead(point, brakes):
    sim = simple()
    sim.nav_state.set("laser1", scan([point]))
    set_cmd(sim.nav_state, vx=0.3)
    assert sim.manager.update_rt(sim.nav_state) is brakes
    overrides = sim.actions.of("override_velocity")
    assert (overrides == [Twist()]) if brakes else not overrides


def test_no_brake_when_not_moving_forward():
    sim = simple()
    sim.nav_state.set("laser1", scan([(0.4, 0.0, 0.2)]))
    for vx in (0.0, -0.1):
        set_cmd(sim.nav_state, vx=vx, wz=0.5)
        assert not sim.manager.update_rt(sim.nav_state)
    assert not sim.actions.of("override_velocity")


def test_no_brake_while_paused():
    sim = simple()
    sim.nav_state.set("laser1", scan([(0.4, 0.0, 0.2)]))
    set_cmd(sim.nav_state, vx=0.3)
    sim.nav_state.set("navigation_paused", True)
    assert not sim.manager.update_rt(sim.nav_state)


def backwards_laser(namespace: str) -> None:
    """A laser 0.1 m ahead of the footprint, 0.2 m up, looking backwards (yaw = pi)."""
    transform = TransformStamped(
        Header(0.0, "base_footprint"),
        "laser",
        Transform(np.array([0.1, 0.0, 0.2]), np.array([0.0, 0.0, 1.0, 0.0])),
    )
    get_tf_buffer(namespace).set_transform(transform, "test", is_static=True)


def test_points_of_a_laser_frame_are_fused_into_the_footprint_frame():
    sim = simple()
    backwards_laser(sim.namespace)
    # x = -0.35 in the laser frame is 0.45 m ahead of the footprint, at z = 0.2.
    sim.nav_state.set("laser1", scan([(-0.35, 0.0, 0.0)], frame="laser"))
    set_cmd(sim.nav_state, vx=0.3)
    assert sim.manager.update_rt(sim.nav_state)


def test_invalid_perceptions_are_ignored():
    sim = simple()
    sim.nav_state.set("laser1", scan([(0.4, 0.0, 0.2)], valid=False))
    set_cmd(sim.nav_state, vx=0.3)
    assert not sim.manager.update_rt(sim.nav_state)


# ── Deprecated parameters ────────────────────────────────────────────────────────────────────
def test_deprecated_robot_radius_applies_with_a_warning_when_geometry_is_default(caplog):
    with caplog.at_level(logging.WARNING, logger="easynav"):
        sim = simple({"robot_radius": 0.5})
    assert sim.manager.robot_radius == 0.5
    assert "recovery_manager.robot_radius = 0.5 is deprecated" in caplog.text
    sim.nav_state.set("laser1", scan([(0.4, 0.45, 0.2)]))  # inside a 0.5 m wide robot
    set_cmd(sim.nav_state, vx=0.3)
    assert sim.manager.update_rt(sim.nav_state)


def test_deprecated_parameters_are_ignored_when_robot_geometry_is_set(caplog):
    geometry = RobotGeometry(
        radius=0.25, inscribed_radius=0.25, height=1.2, user_set=frozenset({"radius", "height"})
    )
    with caplog.at_level(logging.WARNING, logger="easynav"):
        sim = simple({"robot_radius": 0.5, "max_obstacle_z": 2.0}, geometry=geometry)
    assert sim.manager.robot_radius == 0.25
    assert sim.manager.max_obstacle_z == 1.2
    assert "robot_radius is deprecated and ignored" in caplog.text
    assert "max_obstacle_z is deprecated and ignored" in caplog.text


def test_deprecated_max_obstacle_z_applies_when_height_is_default():
    sim = simple({"max_obstacle_z": 2.0})
    sim.nav_state.set("laser1", scan([(0.4, 0.0, 1.5)]))  # above 0.5, below 2.0
    set_cmd(sim.nav_state, vx=0.3)
    assert sim.manager.update_rt(sim.nav_state)


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("stop_distance", -0.1),
        ("sensors_timeout", 0.0),
        ("max_backup_attempts", 1.5),
        ("rotate_speed", float("nan")),
        ("backup_time", "long"),
    ],
)
def test_bad_parameters_fail_naming_them(name, value):
    with pytest.raises(PluginConfigurationError, match=f"recovery_manager.{name}"):
        simple({name: value})


# ── Non-RT case 1: sensors lost ──────────────────────────────────────────────────────────────
def test_no_new_sensor_data_for_sensors_timeout_requests_a_shutdown_once():
    sim = simple()
    sim.nav_state.set("laser1", scan([(2.0, 0.0, 0.2)], stamp=1000.0))
    sim.run(4.9)
    assert not sim.actions.of("request_shutdown")
    sim.run(0.3)
    assert len(sim.actions.of("request_shutdown")) == 1
    assert "sensors_timeout = 5 s" in sim.actions.of("request_shutdown")[0]
    sim.run(1.0)
    assert len(sim.actions.of("request_shutdown")) == 1


def test_new_sensor_data_keeps_it_running():
    sim = simple()
    for i in range(20):
        sim.nav_state.set("laser1", scan([(2.0, 0.0, 0.2)], stamp=1000.0 + i))
        sim.run(1.0)
    assert not sim.actions.of("request_shutdown")


def test_no_point_sensor_configured_is_not_a_lost_sensor():
    sim = simple()
    sim.run(10.0)
    assert not sim.actions.of("request_shutdown")


def test_a_sensor_that_never_sent_data_counts_from_activation():
    sim = simple()
    sim.nav_state.set(
        "diagnostics.sensors",
        DiagnosticStatus(
            DiagnosticLevel.WARN,
            "sensors",
            "no data: laser1",
            "sensors_node",
            {"no_data": "laser1", "stale": "", "sensors": "laser1"},
        ),
    )
    sim.run(4.9)
    assert not sim.actions.of("request_shutdown")
    sim.run(0.3)
    assert len(sim.actions.of("request_shutdown")) == 1


def test_the_sensor_watch_restarts_on_activation():
    sim = simple()
    sim.nav_state.set("laser1", scan([(2.0, 0.0, 0.2)], stamp=1000.0))
    sim.run(1.0)
    sim.clock.t += 30.0  # EasyNav inactive meanwhile
    sim.manager.schedule.reset()  # what the host node does on activation
    sim.run(4.0)
    assert not sim.actions.of("request_shutdown")


# ── Non-RT case 2: localization lost ─────────────────────────────────────────────────────────
def test_the_sensor_watch_starts_with_simulated_time():
    # use_sim_time: the node clock reads 0 until the first /clock message, which may come
    # seconds into the simulation (regression: it looked like sensors_timeout without data).
    sim = simple()
    sim.nav_state.set(
        "diagnostics.sensors",
        DiagnosticStatus(
            DiagnosticLevel.WARN,
            "sensors",
            "no data: laser1",
            "sensors_node",
            {"no_data": "laser1", "stale": "", "sensors": "laser1"},
        ),
    )
    sim.clock.t = 0.0
    sim.manager.update(sim.nav_state)  # activated, no clock yet
    sim.clock.t = 7.0  # the first /clock: the simulation has been running for 7 s
    sim.run(1.0)
    assert not sim.actions.of("request_shutdown")
    sim.run(4.5)
    assert len(sim.actions.of("request_shutdown")) == 1


def test_localization_lost_holds_progress_and_rotates_until_relocalized():
    sim = simple()
    set_goal(sim.nav_state)
    set_pose(sim.nav_state, 0.0, 0.0, variance=2.0)
    sim.run(1.0)
    assert sim.actions.of("hold_mission_progress") == [True]
    assert sim.manager.mitigation is SimpleMitigation.ROTATE
    assert sim.takeovers[-1] == Twist(wz=0.5)
    assert all(t == Twist(wz=0.5) for t in sim.takeovers[1:])  # every RT cycle
    set_pose(sim.nav_state, sim.robot.x, sim.robot.y, variance=0.1)
    sim.step()
    assert sim.actions.of("hold_mission_progress") == [True, False]
    sim.step()
    assert sim.takeovers[-1] is None


def test_not_relocalized_in_relocalize_timeout_aborts_the_mission():
    sim = simple({"relocalize_timeout": 3.0})
    set_goal(sim.nav_state)
    set_pose(sim.nav_state, 0.0, 0.0, variance=2.0)
    sim.run(2.9)
    assert not sim.actions.of("abort_mission")
    sim.run(0.3)
    (reason,) = sim.actions.of("abort_mission")
    assert "could not relocalize" in reason
    assert sim.actions.of("hold_mission_progress")[-1] is False
    sim.run(1.0)  # the abort is being applied: nothing else happens
    assert len(sim.actions.of("abort_mission")) == 1
    assert sim.takeovers[-1] is None


# ── Non-RT case 3: stuck ─────────────────────────────────────────────────────────────────────
def stuck_sim(**params) -> Sim:
    sim = simple(params, robot=Robot(held=True))
    set_goal(sim.nav_state)
    set_cmd(sim.nav_state, vx=0.3)
    return sim


def test_stuck_backs_up_for_backup_time_then_the_controller_drives_again():
    sim = stuck_sim()
    sim.run(9.9)
    assert sim.manager.mitigation is SimpleMitigation.NONE
    sim.run(0.2)
    assert sim.manager.mitigation is SimpleMitigation.BACK_UP
    assert sim.takeovers[-1] == Twist(vx=-0.1)
    backing = sim.run(5.0, until=lambda: sim.manager.mitigation is SimpleMitigation.NONE)
    assert 1.9 <= backing <= 2.2
    sim.step()
    assert sim.takeovers[-1] is None  # the controller drives


def test_stuck_after_max_backup_attempts_slows_down_then_aborts():
    sim = stuck_sim()
    sim.run(3 * 12.2 + 10.5)
    assert sim.manager.backup_attempts == 4
    (request,) = sim.actions.of("request_reconfigure")
    assert request[0] == [("controller_node", "robot_limits.max_linear_vel", 0.1)]
    assert not sim.actions.of("abort_mission")
    # The reconfiguration reloads the manager: the new one knows it slowed down from NavState.
    sim.nav_state.set("reconfigured_parameters", ["controller_node/robot_limits.max_linear_vel"])
    sim.manager = SimpleRecoveryManager()
    sim.manager.initialize(sim.context, "recovery_manager")
    sim.run(3 * 12.2 + 10.5)
    (reason,) = sim.actions.of("abort_mission")
    assert "stuck after 3 backup attempts at the reduced speed" in reason
    assert len(sim.actions.of("request_reconfigure")) == 1


def test_stuck_without_slow_down_aborts_after_the_backups():
    sim = stuck_sim(slow_down_max_linear_vel=0.0)
    sim.run(3 * 12.2 + 10.5)
    assert not sim.actions.of("request_reconfigure")
    assert sim.actions.of("abort_mission") == ["stuck after 3 backup attempts"]


def test_a_refused_slow_down_aborts():
    sim = stuck_sim(max_backup_attempts=0)
    sim.actions.reconfigure_accepted = False
    sim.run(10.5)
    assert len(sim.actions.of("request_reconfigure")) == 1
    assert "slowing down was refused" in sim.actions.of("abort_mission")[0]


def test_a_paused_robot_is_not_stuck():
    sim = stuck_sim()
    sim.nav_state.set("navigation_paused", True)
    sim.run(25.0)
    assert sim.manager.mitigation is SimpleMitigation.NONE
    assert all(t is None for t in sim.takeovers)


def test_a_moving_robot_is_not_stuck():
    sim = simple()
    set_goal(sim.nav_state)
    set_cmd(sim.nav_state, vx=0.3)
    sim.run(25.0)
    assert sim.robot.x > 7.0
    assert sim.manager.backup_attempts == 0


def test_the_slow_down_is_undone_when_the_mission_ends():
    sim = simple()
    sim.nav_state.set("reconfigured_parameters", ["controller_node/robot_limits.max_linear_vel"])
    clear_goal(sim.nav_state)
    sim.run(1.0)
    assert len(sim.actions.of("request_restore_parameters")) == 1


# ── Priorities: the most severe case first ───────────────────────────────────────────────────
def test_lost_sensors_come_before_a_lost_localization():
    sim = simple()
    set_goal(sim.nav_state)
    sim.nav_state.set("laser1", scan([(2.0, 0.0, 0.2)], stamp=1000.0))
    set_pose(sim.nav_state, 0.0, 0.0, variance=2.0)
    sim.run(6.0)
    assert len(sim.actions.of("request_shutdown")) == 1
    assert sim.manager.mitigation is SimpleMitigation.NONE  # the rotation was stopped
    assert sim.takeovers[-1] is None


def test_a_lost_localization_comes_before_being_stuck():
    sim = stuck_sim()
    sim.run(11.0)
    assert sim.manager.mitigation is SimpleMitigation.BACK_UP
    set_pose(sim.nav_state, 0.0, 0.0, variance=2.0)
    sim.step()
    assert sim.manager.mitigation is SimpleMitigation.ROTATE
    assert sim.takeovers[-1] == Twist(wz=0.5)


def test_the_brake_overrides_but_never_during_its_own_backup():
    sim = stuck_sim()

    def step_with_scan():
        sim.nav_state.set("laser1", scan([(0.4, 0.0, 0.2)], stamp=sim.clock.t))
        sim.step()

    for _ in range(10):
        step_with_scan()
    assert all(o == Twist() for o in sim.overrides)  # braking the controller every cycle
    for _ in range(200):
        step_with_scan()
    assert not sim.actions.of("request_shutdown")
    # Backing up is not moving forward: no brake while the backup drives.
    backing = [i for i, t in enumerate(sim.takeovers) if t == Twist(vx=-0.1)]
    assert backing
    assert all(sim.overrides[i] is None for i in backing)


def test_context_without_ros_is_enough():
    context = make_context()
    manager = SimpleRecoveryManager()
    context.services = PluginServices(recovery_actions=None)
    manager.initialize(context, "recovery_manager")
    assert manager.stop_distance == 0.3 and manager.max_backup_attempts == 3


def test_robot_geometry_set_to_its_default_values_still_takes_precedence():
    # As in the original EasyNav, robot_geometry takes precedence when both are set, whatever
    # the value.
    geometry = RobotGeometry(user_set=frozenset({"radius", "height"}))
    sim = simple({"robot_radius": 0.5, "max_obstacle_z": 2.0}, geometry=geometry)
    assert sim.manager.robot_radius == 0.3
    assert sim.manager.max_obstacle_z == 0.5
