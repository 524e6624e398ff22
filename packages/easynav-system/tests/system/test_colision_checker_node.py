"""controller_node's colision_checker.* parameters and its check after the controller."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.core.types import Header, Twist, TwistStamped
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def test_inactive_by_default(params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    assert rt.system_node.subnodes["controller_node"].colision_checker is None


def test_active_checker_zeroes_a_command_into_a_point(params_file, runtime_factory):
    document = system_params(**{
        "controller_node.colision_checker.active": True,
        "controller_node.colision_checker.robot_radius": 0.3,
    })
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    node = rt.system_node.subnodes["controller_node"]
    assert node.colision_checker is not None and node.colision_checker.robot_radius == 0.3
    node.active = False  # keep the dummy controller from writing cmd_vel meanwhile
    nav_state = node.nav_state
    frame = node.robot_frame()
    nav_state.set("scan", PointPerception(np.array([[0.5, 0.0, 0.2]]), frame, 0.0))
    command = TwistStamped(Header(1.0, "base_footprint"), Twist(vx=0.5, wz=0.0))
    nav_state.set("cmd_vel", command)
    node.check_collision()
    stopped = nav_state.get("cmd_vel", TwistStamped)
    assert stopped.twist.is_zero() and stopped.header.frame_id == "base_footprint"
    # A command that turns away from the point and one beside it pass unchanged.
    nav_state.set("scan", PointPerception(np.array([[0.5, 0.5, 0.2]]), frame, 0.0))
    nav_state.set("cmd_vel", command)
    node.check_collision()
    assert nav_state.get("cmd_vel", TwistStamped) is command


def _rosout(ros) -> list[str]:
    # Every log message of every node (transient local: those logged before arrive too).
    from rcl_interfaces.msg import Log
    from rclpy.qos import QoSDurabilityPolicy, QoSProfile

    texts: list[str] = []
    qos = QoSProfile(depth=1000, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
    ros.create_node("checker_rosout").create_subscription(
        Log, "/rosout", lambda m: texts.append(m.msg), qos)
    return texts


def _active_checker(ros, params_file, runtime_factory, params):
    # EasyNav started with the check active and ``params``: its checker and the log.
    log = _rosout(ros)
    rt = runtime_factory(params_file(system_params(
        **{"controller_node.colision_checker.active": True, **params})))
    assert rt.start(), rt.error
    return rt.system_node.subnodes["controller_node"].colision_checker, log


@pytest.mark.parametrize("params, shape, expected", [
    pytest.param(
        {"system_node.robot_geometry.radius": 0.45, "system_node.robot_geometry.height": 0.8,
         "controller_node.colision_checker.robot_radius": 0.3},
        (0.45, 0.8),
        ["controller_node.colision_checker.robot_radius is deprecated and ignored: "
         "system_node.robot_geometry.radius = 0.45 takes precedence"],
        id="robot_geometry wins",
    ),
    pytest.param(
        {"controller_node.colision_checker.robot_radius": 0.25,
         "controller_node.colision_checker.robot_height": 1.2},
        (0.25, 1.2),
        ["controller_node.colision_checker.robot_radius = 0.25 is deprecated: set "
         "system_node.robot_geometry.radius instead",
         "controller_node.colision_checker.robot_height = 1.2 is deprecated: set "
         "system_node.robot_geometry.height instead"],
        id="the copies where robot_geometry is unset",
    ),
])
def test_checker_takes_the_robot_shape_from_robot_geometry(ros, params_file, runtime_factory,
                                                           params, shape, expected):
    """robot_geometry configures the checked circle and height; the original's own copies
    still apply where it does not, are ignored where it does, and the whole check is
    deprecated (braking before an obstacle is the recovery system's job): each said once in
    the log."""
    checker, log = _active_checker(ros, params_file, runtime_factory, params)
    assert (checker.robot_radius, checker.robot_height) == shape
    expected = [*expected, "controller_node.colision_checker.active is deprecated: braking "
                "before an obstacle is the recovery system's job"]
    assert ros.spin_until(lambda: all(any(e in t for t in log) for e in expected), timeout=5.0)
    assert [sum(e in t for t in log) for e in expected] == [1] * len(expected)
    copies = [name for name in ("robot_radius", "robot_height")
              if f"controller_node.colision_checker.{name}" in params]
    assert all(any(c in t for c in copies) for t in log if "colision_checker.robot_" in t)


def test_checker_shape_defaults_to_robot_geometry_and_takes_a_point_robot(
        ros, params_file, runtime_factory):
    """Neither set: robot_geometry's defaults (0.3 m, 0.5 m; the original's copy said 0.35 m).
    robot_geometry's legal 0 (a point robot) is the check's too."""
    checker, _ = _active_checker(ros, params_file, runtime_factory, {})
    assert (checker.robot_radius, checker.robot_height) == (0.3, 0.5)
    checker, _ = _active_checker(ros, params_file, runtime_factory,
                                 {"system_node.robot_geometry.radius": 0.0})
    assert checker.robot_radius == 0.0


def test_bad_value_fails_configuration_naming_it(params_file, runtime_factory):
    document = system_params(**{"controller_node.colision_checker.brake_acc": -1.0})
    rt = runtime_factory(params_file(document))
    assert not rt.start()
    assert "colision_checker.brake_acc = -1.0" in rt.error


def _markers_setup(ros, params_file, runtime_factory, debug_markers: bool):
    from visualization_msgs.msg import MarkerArray

    document = system_params(**{
        "controller_node.colision_checker.active": True,
        "controller_node.colision_checker.debug_markers": debug_markers,
        "controller_node.colision_checker.robot_radius": 0.3,
    })
    rt = runtime_factory(params_file(document))
    assert rt.start(), rt.error
    node = rt.system_node.subnodes["controller_node"]
    node.active = False  # keep the dummy controller from writing cmd_vel meanwhile
    probe = ros.create_node("collision_area_probe")
    received: list = []
    probe.create_subscription(MarkerArray, "collision_area", received.append, 10)
    return node, probe, received


def test_debug_markers_publish_the_checked_box_and_points(ros, params_file, runtime_factory):
    """colision_checker.debug_markers: each check publishes the original's MarkerArray on
    collision_area: DELETEALL, the box (CUBE) and the points in it (SPHERE_LIST), in the
    robot frame, red on a collision and green otherwise, alpha 0.25, lifetime 0.2 s."""
    from visualization_msgs.msg import Marker

    node, probe, received = _markers_setup(ros, params_file, runtime_factory, True)
    publisher = node.collision_marker_publisher
    assert publisher is not None
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)
    nav_state, frame = node.nav_state, node.robot_frame()

    def check(points, vx: float) -> list:
        count = len(received)
        nav_state.set("scan", PointPerception(np.array(points), frame, 0.0))
        nav_state.set("cmd_vel", TwistStamped(Header(1.0, "base_footprint"), Twist(vx=vx)))
        node.check_collision()
        assert ros.spin_until(lambda: len(received) > count, timeout=5.0)
        return received[-1].markers

    # A point 0.5 m ahead at 0.5 m/s: stopped, red. Box: radius 0.3 + margin 0.1, stretched
    # ahead by v²/(2·brake_acc) = 0.25 m: x [-0.4, 0.65], y [-0.4, 0.4], z [0, 0.5] (height).
    clear, box, points = check([[0.5, 0.0, 0.2], [1.5, 0.0, 0.2]], 0.5)
    assert nav_state.get("cmd_vel", TwistStamped).twist.is_zero()
    assert clear.action == Marker.DELETEALL and clear.ns == "collision_zone"
    assert (box.type, box.id, points.type, points.id) == (Marker.CUBE, 1, Marker.SPHERE_LIST, 2)
    for m in (box, points):
        assert m.header.frame_id == frame and m.ns == "collision_zone"
        assert (m.color.r, m.color.g, m.color.a) == pytest.approx((1.0, 0.0, 0.25))
        assert (m.lifetime.sec, m.lifetime.nanosec) == (0, 200_000_000)
    assert (box.pose.position.x, box.pose.position.y, box.pose.position.z) == pytest.approx(
        (0.125, 0.0, 0.25))
    assert (box.scale.x, box.scale.y, box.scale.z) == pytest.approx((1.05, 0.8, 0.5))
    assert len(points.points) == 1
    p = points.points[0]
    assert (p.x, p.y, p.z) == pytest.approx((0.5, 0.0, 0.2), abs=0.05)  # a 0.1 m voxel
    # A point beside the box: the command passes, green, no point in the box.
    _, box, points = check([[0.5, 0.6, 0.2]], 0.5)
    assert not nav_state.get("cmd_vel", TwistStamped).twist.is_zero()
    assert (box.color.r, box.color.g) == pytest.approx((0.0, 1.0)) and points.points == []
    # Standing still is checked too (as the original): the box without a stopping stretch.
    _, box, _ = check([[0.5, 0.0, 0.2]], 0.0)
    assert box.scale.x == pytest.approx(0.8) and box.color.g == pytest.approx(1.0)


def test_no_markers_without_debug_markers_and_a_runtime_switch(ros, params_file,
                                                               runtime_factory):
    from rclpy.parameter import Parameter

    node, _probe, received = _markers_setup(ros, params_file, runtime_factory, False)
    assert node.collision_marker_publisher is None

    def check() -> None:
        node.nav_state.set("scan", PointPerception(np.array([[0.5, 0.0, 0.2]]),
                                                   node.robot_frame(), 0.0))
        node.nav_state.set("cmd_vel", TwistStamped(Header(1.0, "base_footprint"), Twist(vx=0.5)))
        node.check_collision()
        assert node.nav_state.get("cmd_vel", TwistStamped).twist.is_zero()  # still checked

    check()
    ros.spin_for(0.5)
    assert received == []
    # Switched on at runtime: the next check publishes; switched off: nothing more.
    name = "colision_checker.debug_markers"
    assert node.set_parameters([Parameter(name, value=True)])[0].successful
    publisher = node.collision_marker_publisher
    assert publisher is not None
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)
    check()
    assert ros.spin_until(lambda: len(received) == 1, timeout=5.0)
    assert node.set_parameters([Parameter(name, value=False)])[0].successful
    assert node.collision_marker_publisher is None
    check()
    ros.spin_for(0.5)
    assert len(received) == 1
