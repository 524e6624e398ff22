"""FusionLocalizer inputs without ROS: ``_differential``, ``_relative`` and the Mahalanobis gates
of each input kind (the original's ukf_wrapper.cpp keys), checked against direct computations."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

pytest.importorskip("filterpy")
pytest.importorskip("pyproj")

from easynav.common.sensors import GNSSPerception, ImuPerception  # noqa: E402
from easynav.common.sensors.gnss_perception import (  # noqa: E402
    COVARIANCE_TYPE_DIAGONAL_KNOWN,
    STATUS_FIX,
)
from easynav.core.plugins import (  # noqa: E402
    DictParameters,
    PluginConfigurationError,
    PluginContext,
)
from easynav.core.types import Header, Odometry, Pose, Twist, yaw_to_quaternion  # noqa: E402
from easynav.localizers.fusion.fusion_filter import (  # noqa: E402
    FusionFilter,
    attitude_in,
    pose_in,
    robot_pose_from_child,
)
from easynav.localizers.fusion.fusion_input import FusionInput  # noqa: E402
from easynav.localizers.fusion.fusion_parameters import read_inputs  # noqa: E402
from easynav.localizers.fusion.ukf_filter import (  # noqa: E402
    AX,
    AY,
    DEFAULT_PROCESS_NOISE,
    VX,
    VY,
    VYAW,
    YAW,
    UkfFilter,
)
from easynav.localizers.fusion.utm_projection import UtmProjection  # noqa: E402
from easynav.localizers.fusion_localizer import FusionLocalizer  # noqa: E402

ORIGIN = (40.2834931, -3.8207254, 746.184)
PROJECTION = UtmProjection(*ORIGIN)
XY = [True, True] + [False] * 13
GNSS_VAR = 0.01**2  # a precise receiver: 1 cm per axis


def fix(x: float, y: float, stamp: float, variance: float = GNSS_VAR) -> GNSSPerception:
    lat, lon = PROJECTION.inverse(x, y)
    return GNSSPerception(latitude=lat, longitude=lon, altitude=ORIGIN[2],
                          position_covariance=np.eye(3) * variance,
                          position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN,
                          status=STATUS_FIX, stamp=stamp)


def gnss_filter(**settings) -> FusionFilter:
    """A 2D global filter with one GNSS input (x, y): pose known, vx and vy unknown; heading,
    yaw rate and accelerations held (as an IMU would; a UKF with an unobserved heading and
    1 m/s² accelerations loses its positive covariance within a few steps)."""
    source = FusionInput("gps", 0, "gps/fix", list(XY), **settings)
    noise = np.diag(DEFAULT_PROCESS_NOISE)
    for i in (YAW, VYAW, AX, AY):
        noise[i, i] = 1e-6
    ukf = UkfFilter(two_d_mode=True, process_noise=noise, initial_covariance=np.diag(
        [1e-9] * 6 + [1.0, 1.0] + [1e-9] * 7))
    return FusionFilter(ukf, [source], PROJECTION)


def place(filt: FusionFilter, x: float, y: float, yaw: float) -> None:
    """Put the estimate at a known pose (as an initial pose from elsewhere would)."""
    filt.ukf.set_variables([0, 1, YAW], [x, y, yaw], [1e-6, 1e-6, 1e-6])


# -- gpsN_differential ------------------------------------------------------------------------
@pytest.mark.parametrize("heading", [0.0, math.pi / 2, 2.5])
def test_differential_gnss_follows_the_steps_between_fixes_not_their_offset(heading):
    """Fixes 100 m away from the estimate, stepping 0.5 m a second along the robot's heading:
    the estimate moves by the steps (the velocity corrects the position through their
    covariance) and measures vx = 0.5 m/s, vy = 0 in the robot frame. Absolute fixes pull the
    same estimate to where the fixes are."""
    step, n = 0.5, 12
    start = np.array((100.0, 50.0))
    direction = np.array((math.cos(heading), math.sin(heading)))
    ends = {}
    for differential in (True, False):
        filt = gnss_filter(differential=differential)
        assert filt.add_gnss("gps0", fix(*start, stamp=1.0))  # the first fix places the robot
        np.testing.assert_allclose(filt.ukf.state[:2], start, atol=1e-6)
        place(filt, 0.0, 0.0, heading)  # ... and the robot is known to be elsewhere
        for k in range(1, n + 1):
            filt.add_gnss("gps0", fix(*(start + k * step * direction), stamp=1.0 + k))
        ends[differential] = filt.ukf.state
    moved = ends[True][:2]
    np.testing.assert_allclose(moved, n * step * direction, atol=0.05)
    assert ends[True][VX] == pytest.approx(step, abs=0.01)
    assert ends[True][VY] == pytest.approx(0.0, abs=0.01)
    assert np.linalg.norm(ends[False][:2] - (start + n * step * direction)) < 0.1


def test_differential_gnss_velocity_and_variance_match_a_direct_computation():
    """One step: the fused velocity is the update of a Kalman filter with the measurement
    R·(p₁ - p₀)/dt (R: map → robot) and variance (C₀ + C₁)/dt²."""
    filt = gnss_filter(differential=True)
    filt.add_gnss("gps0", fix(3.0, 4.0, stamp=10.0, variance=0.04))
    place(filt, 3.0, 4.0, math.pi / 2)
    before = filt.ukf.covariance
    filt.add_gnss("gps0", fix(3.0, 4.5, stamp=10.5, variance=0.09))  # 0.5 m north in 0.5 s
    state = filt.ukf.state
    # Heading north: 1 m/s north is vx = 1, vy = 0. The prediction over 0.5 s adds Q·dt.
    q = np.diag(filt.ukf.process_noise) * 0.5
    prior = before[VX, VX] + q[VX]
    r = (0.04 + 0.09) / 0.25
    assert state[VX] == pytest.approx(prior / (prior + r) * 1.0, rel=1e-3)
    assert state[VY] == pytest.approx(0.0, abs=1e-6)
    assert filt.accepted["gps0"] == 2


def test_differential_gnss_gate_rejects_a_jump_and_keeps_the_estimate():
    filt = gnss_filter(differential=True, pose_threshold=5.0)
    filt.add_gnss("gps0", fix(0.0, 0.0, stamp=1.0))
    filt.add_gnss("gps0", fix(0.5, 0.0, stamp=2.0))
    assert filt.accepted["gps0"] == 2
    state = filt.ukf.state
    assert not filt.add_gnss("gps0", fix(9.0, 0.0, stamp=2.0))  # not newer: dropped
    assert filt.rejected["gps0"] == 0
    assert not filt.add_gnss("gps0", fix(30.5, 0.0, stamp=3.0))  # 30 m/s
    assert filt.rejected["gps0"] == 1
    # Rejected: only the prediction to t = 3 moved the estimate.
    assert filt.ukf.state[0] == pytest.approx(state[0] + state[VX], abs=1e-6)
    assert filt.ukf.state[VX] == pytest.approx(state[VX], abs=1e-9)
    # The step back out of the jump is rejected too (as robot_localization, the previous fix is
    # the rejected one); the next step is fused again.
    assert not filt.add_gnss("gps0", fix(1.5, 0.0, stamp=4.0))
    assert filt.add_gnss("gps0", fix(2.0, 0.0, stamp=5.0))
    assert filt.rejected["gps0"] == 2
    assert filt.ukf.state[0] == pytest.approx(2.0, abs=0.05)


# -- gpsN_relative ----------------------------------------------------------------------------
def test_relative_gnss_takes_the_first_fix_as_the_origin():
    filt = gnss_filter(relative=True)
    assert filt.add_gnss("gps0", fix(100.0, 50.0, stamp=1.0))
    np.testing.assert_allclose(filt.ukf.state[:2], (0.0, 0.0), atol=1e-6)
    for k in range(1, 6):
        filt.add_gnss("gps0", fix(100.0 + k, 50.0 - k, stamp=1.0 + k))
    np.testing.assert_allclose(filt.ukf.state[:2], (5.0, -5.0), atol=0.05)
    absolute = gnss_filter()
    absolute.add_gnss("gps0", fix(100.0, 50.0, stamp=1.0))
    np.testing.assert_allclose(absolute.ukf.state[:2], (100.0, 50.0), atol=1e-6)


def test_relative_gnss_follows_a_reset_pose():
    filt = gnss_filter(relative=True)
    filt.add_gnss("gps0", fix(100.0, 50.0, stamp=1.0))
    filt.reset_pose(10.0, 20.0, 0.0, np.eye(6) * 1e-4)
    filt.add_gnss("gps0", fix(101.0, 50.0, stamp=2.0))
    np.testing.assert_allclose(filt.ukf.state[:2], (11.0, 20.0), atol=0.05)


# -- imuN_twist_rejection_threshold -----------------------------------------------------------
def _imu(wz: float, stamp: float, yaw: float | None = None, variance: float = 1e-4):
    return ImuPerception(
        orientation=np.array(yaw_to_quaternion(yaw if yaw is not None else 0.0)),
        orientation_covariance=np.eye(3) * variance if yaw is not None else -np.eye(3),
        angular_velocity=np.array((0.0, 0.0, wz)),
        angular_velocity_covariance=np.eye(3) * variance,
        linear_acceleration_covariance=-np.eye(3), stamp=stamp)


def imu_filter(config_indices, **settings) -> FusionFilter:
    config = [i in config_indices for i in range(15)]
    ukf = UkfFilter(two_d_mode=True, initial_covariance=np.diag([1e-9] * 6 + [0.04] * 9))
    return FusionFilter(ukf, [FusionInput("imu", 0, "imu", config, **settings)])


def test_imu_twist_gate_is_the_mahalanobis_distance_of_the_angular_velocity():
    """Distance = |w - vyaw| / sqrt(P_vyaw + R): just under the threshold fused, just over it
    rejected, and a rejected reading leaves state and covariance exactly as they were."""
    threshold, variance = 3.0, 1e-4
    filt = imu_filter({VYAW}, twist_threshold=threshold)
    filt.add_imu("imu0", _imu(0.1, stamp=1.0, variance=variance))
    state, cov = filt.ukf.state, filt.ukf.covariance
    sigma = math.sqrt(cov[VYAW, VYAW] + variance)
    filt.add_imu("imu0", _imu(state[VYAW] + 1.01 * threshold * sigma, stamp=1.0))
    assert filt.rejected["imu0"] == 1
    np.testing.assert_array_equal(filt.ukf.state, state)
    np.testing.assert_array_equal(filt.ukf.covariance, cov)
    filt.add_imu("imu0", _imu(state[VYAW] + 0.99 * threshold * sigma, stamp=1.0))
    assert filt.rejected["imu0"] == 1 and filt.accepted["imu0"] == 2
    assert filt.ukf.state[VYAW] > state[VYAW]


# -- imuN_relative / imuN_differential --------------------------------------------------------
def test_relative_imu_yaw_is_relative_to_the_first_reading():
    filt = imu_filter({YAW}, relative=True)
    filt.add_imu("imu0", _imu(0.0, stamp=1.0, yaw=1.2))
    assert filt.ukf.state[YAW] == pytest.approx(0.0, abs=1e-6)
    for k in range(2, 8):
        filt.add_imu("imu0", _imu(0.0, stamp=float(k), yaw=1.2 + 0.5))
    assert filt.ukf.state[YAW] == pytest.approx(0.5, abs=0.01)


def test_differential_imu_fuses_the_attitude_change_as_a_yaw_rate():
    filt = imu_filter({YAW}, differential=True)
    filt.ukf.set_variables([YAW], [2.0], [1e-6])  # absolute yaw known from elsewhere
    for k in range(12):  # 0.3 rad/s across ±π: 3.0 → ... → -2.98
        filt.add_imu("imu0", _imu(0.0, stamp=1.0 + 0.5 * k,
                                  yaw=math.remainder(3.0 + 0.15 * k, 2 * math.pi)))
    assert filt.ukf.state[VYAW] == pytest.approx(0.3, abs=0.01)
    # Its absolute yaw (3.0 at the start) is not fused: the estimate is 2.0 moved by the rates
    # over 5.5 s (not the IMU's 3.0 + 1.65).
    assert math.remainder(filt.ukf.state[YAW] - (2.0 + 0.3 * 5.5), 2 * math.pi) == \
        pytest.approx(0.0, abs=0.05)


def test_a_late_imu_yaw_is_moved_on_by_the_yaw_rate_before_it_is_fused():
    """Turning on the spot at 1 rad/s, readings every 0.02 s; then a burst of readings 0.4 s
    old arrives after newer ones (a loaded machine). Each late yaw is moved on by the yaw
    rate over its lag: the estimate stays on the turn. Fused as they were, at the estimate's
    time, they pulled the yaw back towards where the robot pointed 0.4 s before."""
    rate = 1.0

    def reading(t: float) -> ImuPerception:
        return _imu(rate, stamp=t, yaw=math.remainder(rate * t, 2 * math.pi))

    filt = imu_filter({YAW, VYAW})
    for k in range(1, 101):  # 2 s of readings in order
        filt.add_imu("imu0", reading(k * 0.02))
    for k in range(81, 91):  # late: stamped 1.62 .. 1.80, after the reading of 2.0
        filt.add_imu("imu0", reading(k * 0.02))
    assert filt.time == pytest.approx(2.0)
    assert math.remainder(filt.ukf.state[YAW] - rate * 2.0, 2 * math.pi) == \
        pytest.approx(0.0, abs=0.01)
    # A late reading older than the estimate is still fused: the rate is what it says.
    assert filt.accepted["imu0"] == 2 * 110


def test_a_late_absolute_pose_is_moved_on_by_the_estimated_motion():
    """A poseN (x, y, yaw) 0.5 s old, fused after newer odometry: where the robot was then,
    moved on by the estimate's velocity (1 m/s along +y here) and yaw rate."""
    pose_input = FusionInput("pose", 0, "pose", [True, True, False, False, False, True]
                             + [False] * 9)
    twist_input = FusionInput("twist", 0, "twist", [False] * 6 + [True, True, False, False,
                                                                  False, True] + [False] * 3)
    ukf = UkfFilter(two_d_mode=True, initial_covariance=np.diag([1e-9] * 6 + [1.0] * 9))
    filt = FusionFilter(ukf, [pose_input, twist_input])
    place(filt, 0.0, 0.0, math.pi / 2)
    for k in range(1, 51):  # 1 s at 1 m/s heading north (+y)
        t = k * 0.02
        filt.add_odometry("twist0", Odometry(header=Header(t, "odom"),
                                             twist=Twist(vx=1.0),
                                             twist_covariance=np.eye(6) * 1e-6))
    state = filt.ukf.state
    late = Odometry(header=Header(0.5, "map"),
                    pose=Pose.from_xy_yaw(state[0], state[1] - 0.5, math.pi / 2),
                    pose_covariance=np.eye(6) * 1e-4)
    filt.add_odometry("pose0", late)
    assert filt.ukf.state[1] == pytest.approx(state[1], abs=0.01)
    assert filt.time == pytest.approx(1.0)


def test_a_measurement_stamped_long_before_the_estimate_is_not_moved_on():
    """A pose stamped 0 (no clock) fused at t = 1000 is not a measurement 1000 s late: moved
    on by the velocity times that lag it threw the estimate 400 m away; beyond MAX_LAG it is
    fused as it is (as robot_localization does)."""
    pose_input = FusionInput("pose", 0, "pose", [True, True] + [False] * 13,
                             pose_threshold=sys.float_info.max)
    ukf = UkfFilter(two_d_mode=True, initial_covariance=np.diag([1.0] * 2 + [1e-9] * 4
                                                                + [1.0] * 9))
    filt = FusionFilter(ukf, [pose_input])
    filt.ukf.set_variables([VX], [0.4], [1e-6])
    filt.add_odometry("pose0", Odometry(header=Header(1000.0, "map"),
                                        pose=Pose.from_xy_yaw(0.0, 0.0, 0.0),
                                        pose_covariance=np.eye(6) * 1e-4))
    before = filt.ukf.state[:2].copy()
    filt.add_odometry("pose0", Odometry(header=Header(0.0, "map"), pose=Pose.from_xy_yaw(
        *before, 0.0), pose_covariance=np.eye(6) * 1e-4))
    assert np.linalg.norm(filt.ukf.state[:2] - before) < 0.01


# -- poseN / odomN ----------------------------------------------------------------------------
def test_differential_pose_is_gated_by_its_rejection_threshold():
    source = FusionInput("pose", 0, "pose", [True, True] + [False] * 13, differential=True,
                         pose_threshold=4.0)
    ukf = UkfFilter(two_d_mode=True, initial_covariance=np.diag([1e-9] * 6 + [0.01] * 9))
    filt = FusionFilter(ukf, [source])

    def pose(x, t):
        return Odometry(header=Header(t, "odom"), pose=Pose.from_xy_yaw(x, 0.0, 0.0),
                        pose_covariance=np.eye(6) * 1e-4)

    filt.add_odometry("pose0", pose(0.0, 1.0))
    filt.add_odometry("pose0", pose(0.1, 2.0))
    filt.add_odometry("pose0", pose(10.0, 3.0))  # 9.9 m/s
    assert filt.accepted["pose0"] == 1 and filt.rejected["pose0"] == 1


def test_pose_in_and_attitude_in_invert_a_composition():
    rng = np.random.default_rng(0)
    for _ in range(20):
        ref = np.concatenate((rng.normal(0, 3, 3), rng.uniform(-0.5, 0.5, 2),
                              rng.uniform(-3, 3, 1)))
        np.testing.assert_allclose(pose_in(ref, ref), np.zeros(6), atol=1e-12)
        np.testing.assert_allclose(attitude_in(ref[3:], ref[3:]), np.zeros(3), atol=1e-12)
    # 2D: a pose 1 m ahead of a robot facing +y is (0, 1) in the map.
    out = pose_in(np.array((1.0, 1.0, 0.0, 0.0, 0.0, math.pi / 2)),
                  np.array((1.0, 2.0, 0.0, 0.0, 0.0, math.pi / 2 + 0.3)))
    np.testing.assert_allclose(out, (1.0, 0.0, 0.0, 0.0, 0.0, 0.3), atol=1e-12)


# -- parameters -------------------------------------------------------------------------------
BASE = {
    "Ukf.latitude_origin": ORIGIN[0], "Ukf.longitude_origin": ORIGIN[1],
    "Ukf.global_filter.two_d_mode": True, "Ukf.global_filter.publish_tf": False,
    "Ukf.global_filter.imu0": "imu/data",
    "Ukf.global_filter.imu0_config": [False] * 5 + [True] + [False] * 5 + [True] + [False] * 3,
    "Ukf.global_filter.gps0": "gps/fix", "Ukf.global_filter.gps0_config": XY,
}


def configure(**params) -> FusionLocalizer:
    plugin = FusionLocalizer()
    plugin.initialize(PluginContext(parameters=DictParameters({**BASE, **params}),
                                    namespace="fusion_inputs"), "Ukf")
    return plugin


def test_the_original_keys_reach_the_inputs():
    plugin = configure(**{"Ukf.global_filter.gps0_differential": True,
                          "Ukf.global_filter.gps0_rejection_threshold": 4.0,
                          "Ukf.global_filter.imu0_relative": True,
                          "Ukf.global_filter.imu0_twist_rejection_threshold": 2.5})
    inputs = plugin.filters["global_filter"].inputs
    assert inputs["gps0"].differential and not inputs["gps0"].relative
    assert inputs["gps0"].pose_threshold == 4.0
    assert inputs["imu0"].relative and inputs["imu0"].twist_threshold == 2.5
    plugin = configure(**{"Ukf.global_filter.gps0_relative": True,
                          "Ukf.global_filter.imu0_angular_velocity_rejection_threshold": 1.5})
    inputs = plugin.filters["global_filter"].inputs
    assert inputs["gps0"].relative and inputs["imu0"].twist_threshold == 1.5
    assert inputs["imu0"].pose_threshold == sys.float_info.max  # no gate by default


def test_differential_wins_over_relative_with_a_warning():
    warnings: list[str] = []
    access = DictParameters({"f.gps0": "gps", "f.gps0_config": XY,
                             "f.gps0_differential": True, "f.gps0_relative": True})
    (source,) = read_inputs(access, "f", warn=warnings.append)
    assert source.differential and not source.relative
    assert warnings and "f.gps0_differential" in warnings[0]


@pytest.mark.parametrize(("key", "value"), [
    ("imu0_twist_rejection_threshold", 0.0),
    ("imu0_twist_rejection_threshold", "high"),
    ("gps0_differential", "yes"),
    ("gps0_relative", 1.5),
])
def test_bad_values_name_the_parameter(key, value):
    with pytest.raises(PluginConfigurationError, match=f"global_filter.{key}"):
        configure(**{f"Ukf.global_filter.{key}": value})


def test_the_two_names_of_the_imu_twist_gate_must_agree():
    with pytest.raises(PluginConfigurationError,
                       match="imu0_twist_rejection_threshold.*imu0_angular_velocity"):
        configure(**{"Ukf.global_filter.imu0_twist_rejection_threshold": 2.0,
                     "Ukf.global_filter.imu0_angular_velocity_rejection_threshold": 3.0})
    plugin = configure(**{"Ukf.global_filter.imu0_twist_rejection_threshold": 2.0,
                          "Ukf.global_filter.imu0_angular_velocity_rejection_threshold": 2.0})
    assert plugin.filters["global_filter"].inputs["imu0"].twist_threshold == 2.0


# -- odomN_pose_use_child_frame -----------------------------------------------------------------
#: An odometry source mounted 0.5 m ahead of the robot and turned 90° (its child frame).
MOUNT = np.array((0.5, 0.0, 0.0, 0.0, 0.0, math.pi / 2))  # child frame in the robot frame
ROBOT_IN_CHILD = pose_in(MOUNT, np.zeros(6))  # TF child -> robot: the robot in the child frame


def child_pose(robot_x: float, robot_y: float, robot_yaw: float) -> np.ndarray:
    """Where the child frame is when the robot is at ``(robot_x, robot_y, robot_yaw)``."""
    c, s = math.cos(robot_yaw), math.sin(robot_yaw)
    return np.array((robot_x + c * MOUNT[0] - s * MOUNT[1], robot_y + s * MOUNT[0] + c * MOUNT[1],
                     robot_yaw + MOUNT[5]))


def odom_filter(use_child_frame: bool) -> FusionFilter:
    source = FusionInput("odom", 0, "odom", [True, True] + [False] * 3 + [True] + [False] * 9,
                         pose_use_child_frame=use_child_frame)
    ukf = UkfFilter(two_d_mode=True, initial_covariance=np.diag([1.0] * 6 + [1e-6] * 9))
    return FusionFilter(ukf, [source])


def child_odometry(stamp: float, x: float, y: float, yaw: float) -> Odometry:
    return Odometry(header=Header(stamp, "odom"), child_frame_id="odom_sensor",
                    pose=Pose.from_xy_yaw(x, y, yaw), pose_covariance=np.eye(6) * 1e-6)


def test_robot_pose_from_child_inverts_the_mount():
    cov = np.diag([0.04, 1e-4, 1e-6, 1e-6, 1e-6, 0.01])
    pose, rotated = robot_pose_from_child(np.array((*child_pose(1.0, 2.0, 0.3)[:2], 0.0, 0.0,
                                                    0.0, 0.3 + math.pi / 2)), cov,
                                          ROBOT_IN_CHILD)
    np.testing.assert_allclose(pose, (1.0, 2.0, 0.0, 0.0, 0.0, 0.3), atol=1e-12)
    # The covariance turns with the mount (robot_localization: rot6dᵀ · C · rot6d): the child
    # frame's x variance becomes the robot frame's y variance.
    np.testing.assert_allclose(np.diag(rotated)[:2], (1e-4, 0.04), atol=1e-12)


@pytest.mark.parametrize("use_child_frame", [True, False])
def test_pose_use_child_frame_fuses_the_robot_pose_not_the_sensor_pose(use_child_frame):
    """odom0 reports where its child frame (a sensor 0.5 m ahead, turned 90°) is. With
    ``odom0_pose_use_child_frame`` the estimate is the robot's pose; without it the sensor's
    pose is taken as the robot's (0.5 m and 90° off)."""
    filt = odom_filter(use_child_frame)
    for k in range(1, 6):
        x, y, yaw = child_pose(1.0, 2.0, 0.3)
        filt.add_odometry("odom0", child_odometry(float(k), x, y, yaw), ROBOT_IN_CHILD)
    state = filt.ukf.state
    expected = (1.0, 2.0, 0.3) if use_child_frame else child_pose(1.0, 2.0, 0.3)
    np.testing.assert_allclose((state[0], state[1], state[YAW]), expected, atol=1e-3)


def test_pose_use_child_frame_reads_the_mount_from_tf_and_is_a_known_key():
    """The plugin: ``odom0_pose_use_child_frame`` (robot_localization's key) reaches the
    input, and the child -> robot transform comes from EasyNav's TF buffer
    (base_footprint -> odom_sensor, static)."""
    from easynav.common.tf import get_tf_buffer
    from easynav.core.nav_state import NavState
    from easynav.core.types import Transform, TransformStamped

    assert FusionLocalizer.unknown_parameter_keys(
        {"global_filter.odom0_pose_use_child_frame": True}) == []
    assert [k for k, _ in FusionLocalizer.unknown_parameter_keys(
        {"global_filter.pose0_pose_use_child_frame": True})] == [
        "global_filter.pose0_pose_use_child_frame"]  # robot_localization: odometry only
    key = "Ukf.global_filter.odom0_pose_use_child_frame"
    results = {}
    for flag in (True, False):
        namespace = f"fusion_child_frame_{flag}"
        params = {
            "Ukf.global_filter.two_d_mode": True, "Ukf.global_filter.publish_tf": False,
            "Ukf.global_filter.initial_estimate_covariance": [1.0] * 6 + [1e-6] * 9,
            "Ukf.global_filter.odom0": "odom",
            "Ukf.global_filter.odom0_config": [True, True] + [False] * 3 + [True] + [False] * 9,
            key: flag,
        }
        plugin = FusionLocalizer()
        plugin.initialize(PluginContext(parameters=DictParameters(params), namespace=namespace),
                          "Ukf")
        assert plugin.filters["global_filter"].inputs["odom0"].pose_use_child_frame is flag
        get_tf_buffer(namespace).set_transform(TransformStamped(
            Header(0.0, "base_footprint"), "odom_sensor",
            Transform(np.array(MOUNT[:3]), np.array(yaw_to_quaternion(MOUNT[5])))),
            "test", is_static=True)
        nav_state = NavState()
        for k in range(1, 6):
            plugin.add_odometry("global_filter", "odom0",
                                child_odometry(float(k), *child_pose(1.0, 2.0, 0.3)))
            plugin.update_rt(nav_state)
        pose = nav_state.get("robot_pose", Odometry).pose
        results[flag] = (pose.x, pose.y, pose.yaw)
    np.testing.assert_allclose(results[True], (1.0, 2.0, 0.3), atol=1e-3)
    np.testing.assert_allclose(results[False], child_pose(1.0, 2.0, 0.3), atol=1e-3)
