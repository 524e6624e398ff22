"""GpsLocalizer without ROS: UTM positions, initial pose, covariance, the fed-back yaw."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pyproj")

from easynav.common.sensors import GNSSPerception, ImuPerception  # noqa: E402
from easynav.common.sensors.gnss_perception import (  # noqa: E402
    COVARIANCE_TYPE_DIAGONAL_KNOWN,
    STATUS_FIX,
    STATUS_NO_FIX,
)
from easynav.core.nav_state import NavState  # noqa: E402
from easynav.core.plugins import DictParameters, PluginContext  # noqa: E402
from easynav.core.types import Odometry, yaw_to_quaternion  # noqa: E402
from easynav.localizers.fusion.utm_projection import UtmProjection  # noqa: E402
from easynav.localizers.gps_localizer import GpsLocalizer  # noqa: E402

ORIGIN = (40.2834931, -3.8207254)


def _fix(projection, x, y, stamp, sigma=0.5):
    lat, lon = projection.inverse(x, y)
    return GNSSPerception(latitude=lat, longitude=lon, altitude=700.0,
                          position_covariance=np.eye(3) * sigma**2,
                          position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN,
                          status=STATUS_FIX, stamp=stamp)


def _plugin(params=None, namespace="gps_test"):
    plugin = GpsLocalizer()
    values = {f"gps.{k}": v for k, v in (params or {}).items()}
    plugin.initialize(PluginContext(parameters=DictParameters(values), namespace=namespace),
                      "gps")
    return plugin


def test_positions_relative_to_first_fix_with_covariance():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin()
    nav_state = NavState()
    plugin.update(nav_state)
    assert not nav_state.has("robot_pose")  # no fix yet
    plugin.add_fix(_fix(projection, 10.0, 20.0, 1.0))
    plugin.add_fix(GNSSPerception(status=STATUS_NO_FIX, stamp=1.5))  # ignored
    plugin.add_fix(_fix(projection, 13.0, 24.0, 2.0))
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    assert (pose.pose.x, pose.pose.y) == pytest.approx((3.0, 4.0), abs=1e-3)
    assert pose.pose_covariance[0, 0] == pytest.approx(0.25)
    assert pose.header.stamp == 2.0


def test_initial_pose_places_the_first_fix():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin({"initial_pose.x": 5.0, "initial_pose.y": -2.0}, "gps_test_init")
    plugin.add_fix(_fix(projection, 100.0, 100.0, 1.0))
    plugin.add_fix(_fix(projection, 101.0, 100.0, 2.0))
    nav_state = NavState()
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry).pose
    assert (pose.x, pose.y) == pytest.approx((6.0, -2.0), abs=1e-3)


def _imu(yaw, wz, stamp):
    return ImuPerception(orientation=np.array(yaw_to_quaternion(yaw)),
                         orientation_covariance=np.eye(3) * 0.05**2,
                         angular_velocity=np.array((0.0, 0.0, wz)),
                         angular_velocity_covariance=np.eye(3) * 0.01**2, stamp=stamp)


def test_filtered_yaw_is_fed_back_so_gyro_bias_does_not_drift():
    # The robot stands still; the gyro reads a 0.05 rad/s bias. Integrating the raw gyro (the
    # original) drifts 5 rad in 100 s; the fed-back filter stays near the IMU's yaw.
    plugin = _plugin(namespace="gps_test_yaw")
    for k in range(2001):
        plugin.add_imu(_imu(0.5, 0.05, k * 0.05))
    yaw = plugin.estimator.yaw
    # Steady state of yaw = 0.99 (yaw + b dt) + 0.01 y: 0.99 b dt / 0.01 above the IMU yaw.
    assert yaw == pytest.approx(0.5 + 0.99 * 0.05 * 0.05 / 0.01, abs=0.01)
    assert 0.0 < plugin.estimator.yaw_variance < 0.05**2


def test_last_known_pose_moves_the_estimate():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_reset")
    plugin.add_fix(_fix(projection, 0.0, 0.0, 1.0))
    from easynav.core.types import Header, Pose

    plugin.on_last_known_pose(Odometry(header=Header(1.0, "map"),
                                       pose=Pose.from_xy_yaw(7.0, 8.0, 1.0)))
    plugin.add_fix(_fix(projection, 1.0, 0.0, 2.0))
    nav_state = NavState()
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry).pose
    assert (pose.x, pose.y) == pytest.approx((8.0, 8.0), abs=1e-3)
    assert pose.yaw == pytest.approx(1.0)
    assert math.isfinite(pose.x)


def _drive(plugin, projection, fixes):
    """Fixes ``(stamp, x, y)``; returns robot_pose's (x, y) after each (update after each)."""
    nav_state = NavState()
    seen = []
    for stamp, x, y in fixes:
        plugin.add_fix(_fix(projection, x, y, stamp, sigma=0.15))
        plugin.update(nav_state)
        pose = nav_state.get("robot_pose", Odometry).pose
        seen.append((pose.x, pose.y))
    return seen


def test_a_fix_that_jumps_away_is_rejected_and_a_lasting_offset_is_taken():
    """1 m/s east, a fix every 0.2 s; one fix 30 m off (a receiver's multipath jump) is
    rejected: robot_pose stays on the way. Taken as the original took it, robot_pose moved 30 m
    for a fix period. Six fixes in a row 10 m north of a standing robot (it was carried, or the
    estimate was wrong; farther than 5 m/s could take it in 1.2 s): the first five are
    rejected, then the offset is taken."""
    projection = UtmProjection(*ORIGIN)
    fixes = [(0.2 * k, 0.2 * k, 0.0) for k in range(10)]
    fixes[5] = (1.0, 1.0 + 30.0, 0.0)
    gated = _drive(_plugin(namespace="gps_test_gate"), projection, fixes)
    assert max(abs(x - 0.2 * k) for k, (x, _) in enumerate(gated) if k != 5) < 1e-3
    assert gated[5] == pytest.approx((0.8, 0.0), abs=1e-3)  # the last fix taken
    original = _drive(_plugin({"fix_gate_speed": 0.0}, "gps_test_nogate"), projection, fixes)
    assert original[5][0] == pytest.approx(31.0, abs=1e-3)

    plugin = _plugin(namespace="gps_test_carried")
    moved = [(0.2 * k, 0.0, 0.0) for k in range(5)] + [(1.0 + 0.2 * k, 0.0, 10.0)
                                                       for k in range(6)]
    seen = _drive(plugin, projection, moved)
    assert all(y == pytest.approx(0.0, abs=1e-3) for _, y in seen[:10])
    assert seen[10][1] == pytest.approx(10.0, abs=1e-3)
    assert plugin.estimator.rejected_fixes == 5


def test_map_to_odom_puts_the_tf_robot_at_the_estimate_and_odometry_carries_it_on():
    """odom -> robot drives 1 m/s along odom's x (x = t); the fix of t = 1 says (10, 5) and
    the IMU, at t = 1, that the robot faces 0.5 rad (odometry says 0). map -> odom is computed
    once for that fix, so that map -> odom -> robot is the estimate at the fix's time, and
    re-sent stamped with the newest odometry: the TF tree's robot moves on with odometry
    between fixes and through an outage (no fix from t = 1 to 3). The original's static
    identity left it at the odometry's pose, (1, 0) and then (3, 0)."""
    from easynav.common.tf import get_tf_buffer

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin({"initial_pose.x": 10.0, "initial_pose.y": 5.0}, "gps_test_tf")
    buffer = get_tf_buffer("gps_test_tf")

    def odometry(until: float) -> None:
        for k in range(round(until / 0.1) - 2, round(until / 0.1) + 1):
            buffer.set_transform_values("odom", "base_footprint", k * 0.1,
                                        (k * 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), "test")

    odometry(1.2)
    plugin.add_imu(_imu(0.5, 0.0, 1.0))
    plugin.add_fix(_fix(projection, 0.0, 0.0, 1.0))
    plugin.update(NavState())
    stamp, (tx, ty, *_r, qz, qw) = buffer.lookup_transform_values("map", "base_footprint")
    assert stamp == pytest.approx(1.2)  # map -> odom stamped with the newest odometry
    # At t = 1.2: the fix's (10, 5), then 0.2 m on along the IMU's heading.
    assert (tx, ty) == pytest.approx((10.0 + 0.2 * math.cos(0.5), 5.0 + 0.2 * math.sin(0.5)))
    assert 2.0 * math.atan2(qz, qw) == pytest.approx(0.5, abs=1e-6)
    odometry(3.0)  # an outage: odometry only
    plugin.update(NavState())
    stamp, (tx, ty, *_r) = buffer.lookup_transform_values("map", "base_footprint")
    assert stamp == pytest.approx(3.0)
    assert (tx, ty) == pytest.approx((10.0 + 2.0 * math.cos(0.5), 5.0 + 2.0 * math.sin(0.5)))


def test_gate_edge_cases():
    """An unstamped fix is not gated (the time since the last one is unknown); one older than
    the last fix taken is dropped; a handover (on_last_known_pose) starts the count of
    rejections in a row again."""
    from easynav.core.types import Header, Pose

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_edges")
    estimator = plugin.estimator
    assert plugin.add_fix(_fix(projection, 0.0, 0.0, 1.0)) is None
    estimator_position = estimator.position.copy()
    plugin.add_fix(_fix(projection, 8.0, 0.0, 0.0))  # unstamped, 8 m away: taken
    assert estimator.position[0] == pytest.approx(estimator_position[0] + 8.0, abs=1e-3)
    plugin.add_fix(_fix(projection, 8.5, 0.0, 0.5))  # older than the last fix taken (1.0)
    assert estimator.position[0] == pytest.approx(8.0, abs=1e-3)
    for k in range(3):
        plugin.add_fix(_fix(projection, 50.0, 0.0, 1.2 + 0.2 * k))  # rejected, 3 in a row
    plugin.on_last_known_pose(Odometry(header=Header(1.8, "map"),
                                       pose=Pose.from_xy_yaw(8.0, 0.0, 0.0)))
    for k in range(5):  # the count starts again: five more rejected...
        plugin.add_fix(_fix(projection, 50.0, 0.0, 2.0 + 0.2 * k))
        assert estimator.position[0] == pytest.approx(8.0, abs=1e-3)
    plugin.add_fix(_fix(projection, 50.0, 0.0, 3.0))  # ... and the sixth is taken
    assert estimator.position[0] == pytest.approx(50.0, abs=1e-3)
    assert estimator.rejected_fixes == 8 and estimator.released_jumps == 1


def test_a_clock_that_goes_back_starts_a_new_time_line():
    """A simulator restarted: fixes stamped from 0 again after 20 s. Dropped as out of order,
    the estimate stood at the last fix of the old time line for good."""
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_clock")
    for k in range(1, 21):
        plugin.add_fix(_fix(projection, 0.5 * k, 0.0, float(k)))
    plugin.add_fix(_fix(projection, 3.0, 0.0, 19.5))  # out of order by 0.5 s: dropped
    assert plugin.estimator.position[0] == pytest.approx(9.5, abs=1e-3)  # from the first fix
    for k in range(1, 4):  # the new time line, the robot put back near the start
        plugin.add_fix(_fix(projection, 0.3 * k, 0.0, 0.2 * k))
    assert plugin.estimator.position[0] == pytest.approx(0.9 - 0.5, abs=1e-3)


def _odometry_line(buffer, stamps, yaw_rate=0.0):
    """odom -> robot at ``stamps``: 1 m/s along odom's x, turning at ``yaw_rate`` on the spot
    (the position stays on the line: a test of the yaw alone)."""
    for t in stamps:
        buffer.set_transform_values("odom", "base_footprint", t,
                                    (t, 0.0, 0.0, *yaw_to_quaternion(yaw_rate * t)), "test")


def test_the_anchor_pairs_the_imu_yaw_with_odometry_at_one_instant():
    """Turning at 1 rad/s; the IMU reading (t = 1.3) is ahead of the newest odometry (1.2):
    its yaw is moved back by the gyro to 1.2 before it is paired with odometry's yaw there.
    Paired with odometry of 0.1 s before, map -> odom's rotation was 0.1 rad off."""
    from easynav.common.tf import get_tf_buffer

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_yaw_pair")
    buffer = get_tf_buffer("gps_test_yaw_pair")
    _odometry_line(buffer, [0.8, 0.9, 1.0, 1.1, 1.2], yaw_rate=1.0)
    plugin.add_imu(_imu(1.3, 1.0, 1.3))  # the IMU says 1.3 rad at t = 1.3: odometry agrees
    plugin.add_fix(_fix(projection, 0.0, 0.0, 1.0))
    plugin.update(NavState())
    _, (*_r, qz, qw) = buffer.lookup_transform_values("map", "odom")
    assert 2.0 * math.atan2(qz, qw) == pytest.approx(0.0, abs=1e-6)


def test_a_handover_between_fixes_leaves_no_bias():
    """The last fix at t = 1 (x = 1, the robot at 1 m/s); a handover at t = 1.8 puts the robot
    where it truly is, x = 1.8. The next fixes (x = t) land on the robot: the shift compares
    the handover with the estimate at t = 1.8 (the last fix moved on by odometry). Compared
    with the last fix itself, the 0.8 m driven since stayed as a bias."""
    from easynav.common.tf import get_tf_buffer
    from easynav.core.types import Header, Pose

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_handover")
    buffer = get_tf_buffer("gps_test_handover")
    _odometry_line(buffer, [0.1 * k for k in range(0, 25)])
    plugin.add_fix(_fix(projection, 0.0, 0.0, 0.0))
    for t in (0.5, 1.0):
        plugin.add_fix(_fix(projection, t, 0.0, t))
        plugin.update(NavState())
    plugin.on_last_known_pose(Odometry(header=Header(1.8, "map"),
                                       pose=Pose.from_xy_yaw(1.8, 0.0, 0.0)))
    plugin.add_fix(_fix(projection, 2.0, 0.0, 2.0))
    nav_state = NavState()
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry)  # the fix of t = 2 carried on to t = 2.4
    assert (pose.pose.x, pose.header.stamp) == pytest.approx((2.4, 2.4), abs=1e-3)
    _, (tx, *_r) = buffer.lookup_transform_values("map", "base_footprint")  # t = 2.4
    assert tx == pytest.approx(2.4, abs=1e-3)


def test_map_to_odom_is_never_stamped_ahead_of_odometry():
    """Fixes on another clock (1000 s ahead of odometry) and a non-finite gyro reading: map ->
    odom is anchored on the latest odometry and stamped with it, so map -> robot resolves.
    Stamped with the fix, it stood ahead of the rest of the tree and every lookup through map
    failed; a NaN gyro made the yaw NaN for good."""
    from easynav.common.tf import get_tf_buffer

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_clocks")
    buffer = get_tf_buffer("gps_test_clocks")
    _odometry_line(buffer, [0.1 * k for k in range(0, 11)])
    for k, rate in enumerate((0.0, math.nan, 0.0)):  # the NaN between two good readings
        plugin.add_imu(ImuPerception(orientation=np.array(yaw_to_quaternion(0.0)),
                                     orientation_covariance=np.eye(3) * 0.01,
                                     angular_velocity=np.array((0.0, 0.0, rate)),
                                     angular_velocity_covariance=np.eye(3) * 0.01,
                                     stamp=0.8 + 0.1 * k))
    plugin.add_fix(_fix(projection, 0.0, 0.0, 1000.0))
    plugin.update(NavState())
    stamp, (tx, ty, *_r) = buffer.lookup_transform_values("map", "base_footprint")
    assert stamp == pytest.approx(1.0)
    assert (tx, ty) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert math.isfinite(plugin.estimator.yaw)


@pytest.mark.parametrize("case", ["outage", "unstamped", "two handovers"])
def test_a_handover_measures_the_estimate_where_odometry_can(case):
    """Odometry streams in (x = t, the map origin where the first fix was, at odometry's
    x = 1); handovers put the robot where it truly is. Each one's shift compares it with the
    estimate at its stamp, from the anchor of the current fix: odometry from the fix's own
    stamp was gone after an outage longer than TF's history (the next fix landed 28 m off),
    and unknown for an unstamped fix (0.8 m off). The last fix, where the robot is, gives
    robot_pose."""
    from easynav.common.tf import get_tf_buffer
    from easynav.core.types import Header, Pose

    namespace = f"gps_test_handover_{case.replace(' ', '_')}"
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace=namespace)
    buffer = get_tf_buffer(namespace)
    streamed = [0.0]

    def stream(until: float) -> None:  # odometry every 0.1 s up to ``until``
        k = round(streamed[0] / 0.1)
        while k * 0.1 <= until + 1e-9:
            _odometry_line(buffer, [k * 0.1])
            k += 1
        streamed[0] = k * 0.1

    def handover(stamp: float, x: float) -> None:
        plugin.on_last_known_pose(Odometry(header=Header(stamp, "map"),
                                           pose=Pose.from_xy_yaw(x, 0.0, 0.0)))

    # (odometry streamed up to, then a handover (stamp, x) or None), the last fix (x, stamp).
    steps, (last_x, last_stamp) = {
        "outage": ([(29.0, (29.0, 28.0)), (30.0, None)], (29.0, 30.0)),
        "unstamped": ([(1.8, (1.8, 0.8)), (2.4, None)], (1.4, 0.0)),
        "two handovers": ([(1.0, (0.0, 0.0)), (2.0, (2.0, 1.0)), (3.0, None)], (2.0, 3.0)),
    }[case]
    stream(1.0)
    plugin.add_fix(_fix(projection, 0.0, 0.0, 0.0 if case == "unstamped" else 1.0))
    plugin.update(NavState())
    for until, pose in steps:
        stream(until)
        if pose is not None:
            handover(*pose)
    plugin.add_fix(_fix(projection, last_x, 0.0, last_stamp))
    expected = last_x
    nav_state = NavState()
    plugin.update(nav_state)
    assert nav_state.get("robot_pose", Odometry).pose.x == pytest.approx(expected, abs=1e-3)


def test_robot_pose_moves_on_with_odometry_between_fixes_and_through_an_outage():
    """Odometry every 0.1 s (x = t, 1 m/s); fixes at 5 Hz up to t = 1, then none up to t = 16
    (an outage longer than TF's 10 s of history). robot_pose is the last fix carried on by
    odometry to the newest odom -> robot, stamped there, its position variance grown by 5 % of
    the way odometry measured since the fix, never falling back through the outage; the
    original wrote the last fix, which stood 15 m behind the robot at the end of it."""
    from easynav.common.tf import get_tf_buffer
    from easynav.localizers.gps_localizer import ODOMETRY_DRIFT

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin({"initial_pose.x": 10.0, "initial_pose.y": 5.0}, "gps_test_carried")
    buffer = get_tf_buffer("gps_test_carried")
    nav_state = NavState()
    variances = []
    for k in range(0, 161):
        t = 0.1 * k
        _odometry_line(buffer, [t])
        if k <= 10 and k % 2 == 0:
            plugin.add_fix(_fix(projection, t, 0.0, t, sigma=0.15))
        plugin.update(nav_state)
        pose = nav_state.get("robot_pose", Odometry)
        assert (pose.pose.x, pose.pose.y) == pytest.approx((10.0 + t, 5.0), abs=1e-3), t
        assert pose.header.stamp == pytest.approx(t)
        variances.append(pose.pose_covariance[0, 0])
    assert variances[-1] == pytest.approx(0.15**2 + (ODOMETRY_DRIFT * 15.0)**2)
    assert np.all(np.diff(variances[10:]) >= 0.0)


def test_the_way_driven_counts_a_drive_there_and_back():
    """After the fix, odometry drives 2 m on and 2 m back: the variance grows for 4 m, where the
    displacement (0) would claim the pose as sure as the fix."""
    from easynav.common.tf import get_tf_buffer
    from easynav.localizers.gps_localizer import ODOMETRY_DRIFT

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_there_and_back")
    buffer = get_tf_buffer("gps_test_there_and_back")
    nav_state = NavState()
    buffer.set_transform_values("odom", "base_footprint", 0.0, (0, 0, 0, 0, 0, 0, 1), "test")
    plugin.add_fix(_fix(projection, 0.0, 0.0, 0.0, sigma=0.15))
    plugin.update(nav_state)
    for k in range(1, 41):
        x = 0.1 * k if k <= 20 else 0.1 * (40 - k)
        buffer.set_transform_values("odom", "base_footprint", 0.1 * k, (x, 0, 0, 0, 0, 0, 1),
                                    "test")
        plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    assert pose.pose.x == pytest.approx(0.0, abs=1e-6)
    assert pose.pose_covariance[0, 0] == pytest.approx(0.15**2 + (ODOMETRY_DRIFT * 4.0)**2)


def test_an_unstamped_fix_is_carried_from_the_odometry_it_was_anchored_on():
    """A fix without a stamp is anchored on the newest odometry; robot_pose moves on from
    there and its variance grows with the way driven after it."""
    from easynav.common.tf import get_tf_buffer
    from easynav.localizers.gps_localizer import ODOMETRY_DRIFT

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_unstamped_carry")
    buffer = get_tf_buffer("gps_test_unstamped_carry")
    nav_state = NavState()
    _odometry_line(buffer, [0.0, 0.1, 0.2])
    plugin.add_fix(_fix(projection, 0.0, 0.0, 0.0, sigma=0.15))
    plugin.update(nav_state)  # anchored on odometry's x = 0.2
    for k in range(3, 13):
        _odometry_line(buffer, [0.1 * k])
        plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    assert pose.pose.x == pytest.approx(1.0, abs=1e-6)
    assert pose.pose_covariance[0, 0] == pytest.approx(0.15**2 + (ODOMETRY_DRIFT * 1.0)**2)


def test_map_to_odom_and_robot_pose_come_from_one_look_at_odometry(monkeypatch):
    """Odometry lands (in the RT thread) while an update runs: ``map → odom`` and robot_pose
    are both from the one ``odom → robot`` sample the update looked at, stamped alike. Looked
    up twice, robot_pose came from the newer sample while ``map → odom`` was stamped with the
    older."""
    from easynav.common.tf import get_tf_buffer

    projection = UtmProjection(*ORIGIN)
    plugin = _plugin({"initial_pose.x": 10.0, "initial_pose.y": 5.0}, "gps_test_one_look")
    buffer = get_tf_buffer("gps_test_one_look")
    nav_state = NavState()
    _odometry_line(buffer, [0.0, 0.1])
    plugin.add_fix(_fix(projection, 0.1, 0.0, 0.1, sigma=0.15))
    real = buffer.lookup_transform_values

    def lookup(target, source, time=None):
        result = real(target, source, time)
        if (target, source, time) == ("odom", "base_footprint", None):
            _odometry_line(buffer, [result[0] + 0.1])  # the next sample lands meanwhile
        return result

    monkeypatch.setattr(buffer, "lookup_transform_values", lookup)
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    sent, _ = real("map", "odom")
    assert pose.header.stamp == pytest.approx(sent) == pytest.approx(0.1)
    assert (pose.pose.x, pose.pose.y) == pytest.approx((10.0, 5.0), abs=1e-3)  # the fix
