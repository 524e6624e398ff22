"""CollisionSafetyReflex without ROS: stopping-distance box, closest approach, fail-safe."""

from __future__ import annotations

import numpy as np
import pytest
from recovery_harness import Clock, RecordingActions, make_context, scan

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.types import DiagnosticLevel, Header, Transform, TransformStamped, Twist
from easynav.recovery.diagnostic.reflexes import CollisionSafetyReflex
from easynav.recovery.diagnostic.reflexes.collision_safety_reflex import first_collision

ALIAS = "recovery_manager.collision"


def make_reflex(params=None, clock=None):
    nav_state = NavState()
    actions = RecordingActions(nav_state)
    context = make_context({f"{ALIAS}.{k}": v for k, v in (params or {}).items()}, clock,
                           actions)
    reflex = CollisionSafetyReflex()
    reflex.initialize(context, ALIAS)
    return reflex, nav_state, actions


def brakes(point, twist: Twist, params=None) -> bool:
    reflex, nav_state, actions = make_reflex(params)
    nav_state.set("laser1", scan([point]))
    triggered = reflex.check_and_mitigate(nav_state, twist)
    assert triggered == bool(actions.of("override_velocity"))
    return triggered


# Defaults: radius 0.3 + safety_margin 0.1 = 0.4; brake_acc 0.5 → at 0.5 m/s, 0.25 m to stop.
@pytest.mark.parametrize(
    ("point", "twist", "expected"),
    [
        ((0.6, 0.0, 0.2), Twist(vx=0.5), True),  # within 0.4 + 0.25 ahead
        ((0.7, 0.0, 0.2), Twist(vx=0.5), False),  # beyond the stopping distance
        ((0.6, 0.0, 0.2), Twist(vx=0.2), False),  # slower: 0.04 m to stop
        ((0.6, 0.35, 0.2), Twist(vx=0.5), True),  # its path sweeps the disc
        ((0.6, 0.45, 0.2), Twist(vx=0.5), False),  # beside the swept disc
        ((-0.6, 0.0, 0.2), Twist(vx=-0.5), True),  # backing into it
        ((-0.6, 0.0, 0.2), Twist(vx=0.5), False),  # behind, moving away
        ((0.0, 0.6, 0.2), Twist(vy=0.5), True),  # sideways (holonomic)
        ((0.6, 0.0, 0.7), Twist(vx=0.5), False),  # above robot_geometry.height
        ((0.35, 0.0, 0.2), Twist(wz=1.0), False),  # rotating in place is never braked
    ],
)
def test_brakes_exactly_for_points_it_would_hit_before_stopping(point, twist, expected):
    assert brakes(point, twist) is expected


def test_a_point_inside_the_disc_allows_moving_away_but_not_closer():
    assert not brakes((-0.2, 0.0, 0.2), Twist(vx=0.3))
    assert brakes((0.2, 0.0, 0.2), Twist(vx=0.3))


def test_the_safety_margin_widens_the_robot():
    point = (0.5, 0.45, 0.2)
    assert not brakes(point, Twist(vx=0.5))
    assert brakes(point, Twist(vx=0.5), {"safety_margin": 0.2})


def test_z_min_filter_ignores_the_ground():
    assert brakes((0.5, 0.0, 0.0), Twist(vx=0.5))
    assert not brakes((0.5, 0.0, 0.0), Twist(vx=0.5), {"z_min_filter": 0.05})


def test_turning_into_a_point_is_a_collision():
    # Going straight, the robot stops 0.403 m from the point: just clear of the 0.4 m disc.
    point = (0.6, 0.39, 0.2)
    assert not brakes(point, Twist(vx=0.5))
    assert brakes(point, Twist(vx=0.5, wz=0.5))  # turning towards it
    assert not brakes(point, Twist(vx=0.5, wz=-0.5))  # turning away


def test_fails_safe_without_a_valid_perception_but_lets_it_rotate():
    reflex, nav_state, actions = make_reflex()
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.2))
    assert "no valid point perception" in reflex.reason
    assert not reflex.check_and_mitigate(nav_state, Twist(wz=0.8))
    nav_state.set("laser1", scan([(0.5, 0.0, 0.2)], valid=False))  # expired data
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.2))
    assert actions.of("override_velocity") == [Twist(), Twist()]


def test_fails_safe_when_no_perception_can_be_transformed():
    reflex, nav_state, _ = make_reflex()
    nav_state.set("laser1", scan([(3.0, 0.0, 0.2)], frame="unknown_laser"))
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.2))
    assert "cannot be transformed" in reflex.reason or "can be transformed" in reflex.reason


def test_fuses_perceptions_of_other_frames():
    reflex, nav_state, _ = make_reflex()
    ts = TransformStamped(
        Header(0.0, "base_footprint"),
        "laser",
        Transform(np.array([0.2, 0.0, 0.2]), np.array([0.0, 0.0, 0.0, 1.0])),
    )
    get_tf_buffer(reflex.context.namespace).set_transform(ts, "test", is_static=True)
    nav_state.set("laser1", scan([(0.4, 0.0, 0.0)], frame="laser"))  # 0.6 m ahead
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.5))


def _odometry(reflex, samples) -> None:
    """odom -> base_footprint transforms ``(stamp, x, y, yaw)``."""
    from easynav.core.types import yaw_to_quaternion

    buffer = get_tf_buffer(reflex.context.namespace)
    for stamp, x, y, yaw in samples:
        buffer.set_transform_values("odom", "base_footprint", stamp,
                                    (x, y, 0.0, *yaw_to_quaternion(yaw)), "test")


def test_points_are_moved_by_the_robots_motion_since_the_scan():
    """A scan 0.4 s old (a loaded machine): the robot has driven 0.2 m since. The point seen
    0.8 m ahead is 0.6 m ahead now, inside the stopping box at 0.5 m/s (0.4 + 0.25): brake.
    Measured from where the robot was when the laser fired, it was not."""
    reflex, nav_state, actions = make_reflex(clock=Clock(1000.4))
    nav_state.set("laser1", scan([(0.8, 0.0, 0.2)], stamp=1000.0))
    _odometry(reflex, [(1000.0, 3.0, 1.0, 0.0), (1000.2, 3.1, 1.0, 0.0),
                       (1000.4, 3.2, 1.0, 0.0)])
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
    assert "(0.60, 0.00)" in reflex.reason
    assert reflex._cloud.points_stamp == 1000.4  # as of the newest odometry: no latency


def test_what_no_odometry_has_told_yet_is_driven_at_the_command():
    """The same scan, 0.4 s old, and odometry that stops at the scan's stamp (it is late too):
    the robot has driven on at the commanded 0.5 m/s for 0.4 s since, so the stopping box
    starts 0.2 m further out. Without that latency the point was beyond it."""
    for now, expected in ((1000.0, False), (1000.4, True)):
        reflex, nav_state, _ = make_reflex(clock=Clock(now))
        nav_state.set("laser1", scan([(0.8, 0.0, 0.2)], stamp=1000.0))
        _odometry(reflex, [(999.8, 3.0, 1.0, 0.0), (1000.0, 3.1, 1.0, 0.0)])
        assert reflex.check_and_mitigate(nav_state, Twist(vx=0.5)) is expected


def test_first_collision_with_latency_against_the_stopping_distance():
    """Straight ahead at v: the point is hit when it lies within R + v·latency + v²/(2a)."""
    v, a, reach, latency = 0.4, 0.5, 0.4, 0.3
    edge = reach + v * latency + v * v / (2 * a)
    near = np.array([(edge - 1e-3, 0.0, 0.2)])
    far = np.array([(edge + 1e-3, 0.0, 0.2)])
    assert first_collision(near, v, 0.0, 0.0, reach, a, latency) is not None
    assert first_collision(far, v, 0.0, 0.0, reach, a, latency) is None
    assert first_collision(near, v, 0.0, 0.0, reach, a) is None  # no latency: out of reach


def test_points_carried_through_a_turn():
    """The robot turned 90° left on the spot since the scan: a point seen 1 m ahead is 1 m to
    its right now; one whose stamp odometry does not cover stays where it was seen."""
    reflex, nav_state, _ = make_reflex()
    _odometry(reflex, [(1000.0, 2.0, 2.0, 0.3), (1000.5, 2.0, 2.0, 0.3 + np.pi / 2)])
    nav_state.set("laser1", scan([(1.0, 0.0, 0.2)], stamp=1000.0))
    nav_state.set("laser2", scan([(0.0, 2.0, 0.2)], stamp=1001.0))  # newer than odometry
    reflex._cloud.update(nav_state, "base_footprint")
    carried = reflex._cloud.carried_to_latest("odom")
    np.testing.assert_allclose(carried, [(0.0, -1.0, 0.2), (0.0, 2.0, 0.2)], atol=1e-9)
    assert reflex._cloud.carried_to_latest("odom") is carried  # cached until odometry moves


def test_a_perception_in_the_odom_frame_is_carried_from_the_transform_it_was_fused_with():
    """A cloud in the odom frame (a fixed frame), newer than the last odometry when it is
    fused: the fusion takes the latest transform (t = 1, robot at x = 0.5), so its points are
    where they are relative to the robot *then*; carried from their own stamp (1.5) instead,
    the obstacle came out 0.25 m farther than it is."""
    reflex, nav_state, _ = make_reflex()
    _odometry(reflex, [(0.0, 0.0, 0.0, 0.0), (1.0, 0.5, 0.0, 0.0)])
    nav_state.set("cloud", scan([(2.0, 0.0, 0.2)], frame="odom", stamp=1.5))
    cloud = reflex._cloud
    np.testing.assert_allclose(cloud.update(nav_state, "base_footprint"), [(1.5, 0.0, 0.2)])
    _odometry(reflex, [(2.0, 1.0, 0.0, 0.0)])
    np.testing.assert_allclose(cloud.carried_to_latest("odom"), [(1.0, 0.0, 0.2)], atol=1e-9)


def test_a_transform_sent_again_with_its_stamp_renews_the_carried_points():
    reflex, nav_state, _ = make_reflex()
    _odometry(reflex, [(1.0, 0.0, 0.0, 0.0), (2.0, 0.5, 0.0, 0.0)])
    nav_state.set("laser1", scan([(2.0, 0.0, 0.2)], stamp=1.0))
    cloud = reflex._cloud
    cloud.update(nav_state, "base_footprint")
    np.testing.assert_allclose(cloud.carried_to_latest("odom"), [(1.5, 0.0, 0.2)])
    _odometry(reflex, [(2.0, 0.75, 0.0, 0.0)])  # corrected, same stamp
    np.testing.assert_allclose(cloud.carried_to_latest("odom"), [(1.25, 0.0, 0.2)])


def test_no_command_and_no_motion_are_not_checked():
    reflex, nav_state, _ = make_reflex()
    assert not reflex.check_and_mitigate(nav_state, None)
    assert not reflex.check_and_mitigate(nav_state, Twist())


def test_diagnostic_is_written_on_level_changes_only():
    reflex, nav_state, _ = make_reflex()
    key = f"diagnostics.{ALIAS}"
    nav_state.set("laser1", scan([(0.5, 0.0, 0.2)]))
    reflex.check_and_mitigate(nav_state, Twist(vx=0.0))
    first = nav_state.get(key)
    assert first.level == DiagnosticLevel.OK and first.hardware_id == "safety_reflex"
    reflex.check_and_mitigate(nav_state, Twist(vx=0.0))
    assert nav_state.get(key) is first  # not rewritten
    reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
    warn = nav_state.get(key)
    assert warn.level == DiagnosticLevel.WARN and "imminent collision" in warn.message
    assert key in nav_state.groups()["diagnostics"]


def test_a_failing_check_stops_the_robot_and_reports_an_error(monkeypatch):
    reflex, nav_state, actions = make_reflex()

    def broken(nav_state, commanded):
        raise ValueError("boom")

    monkeypatch.setattr(reflex, "check", broken)
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.1))
    assert actions.of("override_velocity") == [Twist()]
    status = nav_state.get(f"diagnostics.{ALIAS}")
    assert status.level == DiagnosticLevel.ERROR and "boom" in status.message


def test_a_scan_is_fused_once_while_it_stays_the_same(monkeypatch):
    reflex, nav_state, _ = make_reflex()
    nav_state.set("laser1", scan([(2.0, 0.0, 0.2)]))
    first = reflex._cloud.update(nav_state, "base_footprint")
    assert reflex._cloud.update(nav_state, "base_footprint") is first
    nav_state.set("laser1", scan([(2.0, 0.0, 0.2)]))  # new data
    assert reflex._cloud.update(nav_state, "base_footprint") is not first


def test_downsampling_keeps_one_point_per_voxel():
    reflex, nav_state, _ = make_reflex({"downsample_leaf_size": 0.5})
    nav_state.set("laser1", scan([(2.01, 0.01, 0.2), (2.02, 0.02, 0.21), (3.0, 0.0, 0.2)]))
    assert reflex._cloud.update(nav_state, "base_footprint").shape == (2, 3)


@pytest.mark.parametrize("name", ["brake_acc", "downsample_leaf_size"])
def test_parameters_must_be_positive(name):
    with pytest.raises(PluginConfigurationError, match=f"{ALIAS}.{name}"):
        make_reflex({name: 0.0})


def test_first_collision_on_an_empty_cloud():
    assert first_collision(np.empty((0, 3)), 0.5, 0.0, 0.0, 0.4, 0.5) is None


# -- debug_markers ------------------------------------------------------------------------------
class FakePublisher:
    def __init__(self, msg_type, topic, qos):
        self.msg_type, self.topic, self.qos = msg_type, topic, qos
        self.published = []

    def publish(self, msg):
        self.published.append(msg)


class FakeNode:
    """The two calls the reflex makes on its node."""

    def __init__(self):
        self.publishers, self.destroyed = [], []

    def create_publisher(self, msg_type, topic, qos):
        self.publishers.append(FakePublisher(msg_type, topic, qos))
        return self.publishers[-1]

    def destroy_publisher(self, publisher):
        self.destroyed.append(publisher)


def test_debug_markers_keep_the_checked_box_and_the_points_in_it():
    """Defaults: reach 0.3 + 0.1, brake_acc 0.5, height 0.5. At 0.5 m/s forward the box is
    x in [-0.4, 0.4 + 0.25], y in [-0.4, 0.4], z in [z_min_filter, height]."""
    reflex, nav_state, _ = make_reflex({"debug_markers": True, "z_min_filter": 0.05})
    nav_state.set("laser1", scan([(0.6, 0.0, 0.2), (2.0, 0.0, 0.2), (0.1, -0.39, 0.3)]))
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
    zone = reflex.last_zone
    assert zone.frame == "base_footprint" and zone.imminent and zone.stamp == 1000.0
    np.testing.assert_allclose(zone.lower, (-0.4, -0.4, 0.05))
    np.testing.assert_allclose(zone.upper, (0.65, 0.4, 0.5))
    np.testing.assert_allclose(zone.points, [(0.6, 0.0, 0.2), (0.1, -0.39, 0.3)])
    # Backing up at 1 m/s with brake_acc 0.5: 1 m behind; the point ahead is outside now.
    assert not reflex.check_and_mitigate(nav_state, Twist(vx=-1.0))
    zone = reflex.last_zone
    assert not zone.imminent
    np.testing.assert_allclose(zone.lower[:2], (-1.4, -0.4))
    np.testing.assert_allclose(zone.upper[:2], (0.4, 0.4))
    np.testing.assert_allclose(zone.points, [(0.1, -0.39, 0.3)])


def test_without_debug_markers_nothing_is_kept_or_published():
    reflex, nav_state, _ = make_reflex()
    assert reflex.params.debug_markers is False  # the original's default
    nav_state.set("laser1", scan([(0.6, 0.0, 0.2)]))
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
    assert reflex.last_zone is None


def test_debug_markers_must_be_a_bool():
    with pytest.raises(PluginConfigurationError, match=f"{ALIAS}.debug_markers"):
        make_reflex({"debug_markers": "sometimes"})


def test_markers_are_the_originals():
    pytest.importorskip("visualization_msgs")
    from visualization_msgs.msg import Marker

    from easynav.recovery.diagnostic.reflexes.collision_safety_reflex import (
        CollisionZone,
        zone_markers,
    )

    zone = CollisionZone("base_footprint", 12.25, (-0.4, -0.4, 0.0), (0.65, 0.4, 0.5),
                         np.array([(0.6, 0.0, 0.2), (np.nan, 0.0, 0.0)]), True)
    delete, box, points = zone_markers(zone).markers
    assert delete.action == Marker.DELETEALL
    assert (box.type, box.action, box.id, box.ns) == (Marker.CUBE, Marker.ADD, 1,
                                                      "collision_zone")
    assert box.header.frame_id == "base_footprint"
    assert (box.header.stamp.sec, box.header.stamp.nanosec) == (12, 250_000_000)
    assert (box.pose.position.x, box.pose.position.y, box.pose.position.z) == \
        pytest.approx((0.125, 0.0, 0.25))
    assert (box.scale.x, box.scale.y, box.scale.z) == pytest.approx((1.05, 0.8, 0.5))
    assert (box.color.r, box.color.g, box.color.a) == pytest.approx((1.0, 0.0, 0.25))
    assert (box.lifetime.sec, box.lifetime.nanosec) == (0, 200_000_000)
    assert points.type == Marker.SPHERE_LIST and points.scale.x == pytest.approx(0.03)
    assert [(p.x, p.y, p.z) for p in points.points] == [pytest.approx((0.6, 0.0, 0.2))]
    clear = CollisionZone("base_footprint", 0.0, (-0.4, -0.4, 0.0), (0.4, 0.4, 0.5),
                          np.empty((0, 3)), False)
    _, box, points = zone_markers(clear).markers
    assert (box.color.r, box.color.g) == (0.0, 1.0) and points.points == []


def test_markers_are_published_on_collision_area_when_asked():
    pytest.importorskip("visualization_msgs")
    import dataclasses

    from visualization_msgs.msg import MarkerArray

    for debug in (True, False):
        nav_state = NavState()
        actions = RecordingActions(nav_state)
        node = FakeNode()
        context = dataclasses.replace(
            make_context({f"{ALIAS}.debug_markers": debug}, None, actions), node=node)
        reflex = CollisionSafetyReflex()
        reflex.initialize(context, ALIAS)
        (publisher,) = node.publishers
        assert (publisher.msg_type, publisher.topic, publisher.qos) == (MarkerArray,
                                                                       "collision_area", 10)
        nav_state.set("laser1", scan([(0.6, 0.0, 0.2)]))
        reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
        reflex.check_and_mitigate(nav_state, Twist(wz=0.5))  # rotating in place: not looked
        assert len(publisher.published) == (1 if debug else 0)
        if debug:
            assert isinstance(publisher.published[0], MarkerArray)
        reflex.on_parameter_changed("debug_markers", not debug)  # a runtime change
        reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
        assert len(publisher.published) == 1
        reflex.on_cleanup()
        assert node.destroyed == [publisher]
