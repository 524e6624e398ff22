"""FusionLocalizer without ROS: tracking with GNSS noise, a GNSS outage, a GNSS jump."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

pytest.importorskip("filterpy")
pytest.importorskip("pyproj")

from easynav.common.sensors import GNSSPerception, ImuPerception  # noqa: E402
from easynav.common.sensors.gnss_perception import (  # noqa: E402
    COVARIANCE_TYPE_DIAGONAL_KNOWN,
    STATUS_FIX,
)
from easynav.core.nav_state import NavState  # noqa: E402
from easynav.core.plugins import (  # noqa: E402
    DictParameters,
    PluginConfigurationError,
    PluginContext,
)
from easynav.core.types import Header, Odometry, Pose, Twist, yaw_to_quaternion  # noqa: E402
from easynav.localizers.fusion.ukf_filter import (  # noqa: E402
    UkfFilter,
    transition,
    transition_batch,
)
from easynav.localizers.fusion.utm_projection import UtmProjection  # noqa: E402
from easynav.localizers.fusion_localizer import ROBOT_POSE_LOCAL, FusionLocalizer  # noqa: E402

_namespaces = itertools.count()
ORIGIN = (40.2834931, -3.8207254, 746.184)  # the original's example origin
RATE = 10.0  # odometry and IMU (Hz)
GNSS_EVERY = 2  # one fix every 2 cycles: 5 Hz
GNSS_SIGMA = 0.8  # m, per axis
DURATION = 150.0
OUTAGE = (60.0, 90.0)
JUMP = (120.0, 122.0)  # fixes 30 m east in this window


def fusion_params(**overrides) -> dict:
    params = {
        "Ukf.latitude_origin": ORIGIN[0],
        "Ukf.longitude_origin": ORIGIN[1],
        "Ukf.altitude_origin": ORIGIN[2],
        "Ukf.global_filter.two_d_mode": True,
        "Ukf.global_filter.odom0": "odom",
        "Ukf.global_filter.odom0_config": [False] * 6 + [True, True, False,
                                                         False, False, True] + [False] * 3,
        "Ukf.global_filter.imu0": "imu/data",
        "Ukf.global_filter.imu0_config": [False] * 5 + [True] + [False] * 5 + [True]
        + [False] * 3,
        "Ukf.global_filter.gps0": "gps/fix",
        "Ukf.global_filter.gps0_config": [True, True] + [False] * 13,
        "Ukf.global_filter.gps0_rejection_threshold": 5.0,
        "Ukf.global_filter.publish_tf": False,  # no odometry TF in these tests
    }
    params.update(overrides)
    return params


class Sim:
    """A robot driving curves for 150 s: wheel odometry with slip (3 % long, yaw-rate bias),
    an IMU (absolute yaw, gyro with bias), GNSS at 5 Hz with 0.8 m noise, an outage, a jump."""

    def __init__(self, params: dict, seed: int = 0) -> None:
        self.rng = np.random.default_rng(seed)
        self.t = 0.0
        self.true = np.array((0.0, 0.0, 0.3))
        self.odom = np.array((0.0, 0.0, 0.3))  # dead reckoning, aligned at the start
        self.projection = UtmProjection(*ORIGIN)
        namespace = f"fusion_test_{next(_namespaces)}"
        context = PluginContext(parameters=DictParameters(params), namespace=namespace,
                                now=lambda: self.t)
        self.plugin = FusionLocalizer()
        self.plugin.initialize(context, "Ukf")
        self.nav_state = NavState()
        self.log: list[tuple] = []  # t, true xy, estimate xy, odometry xy, last fix xy

    def run(self, duration: float = DURATION, outage=OUTAGE, jump=JUMP) -> np.ndarray:
        dt = 1.0 / RATE
        rng = self.rng
        fix_xy = (math.nan, math.nan)
        for k in range(int(duration * RATE)):
            v, w = 1.0, 0.35 * math.sin(2 * math.pi * self.t / 40.0)
            yaw = self.true[2]
            self.true += (v * math.cos(yaw) * dt, v * math.sin(yaw) * dt, w * dt)
            self.t += dt
            # Wheels: 3 % slip in distance, 0.02 rad/s yaw-rate bias, noise.
            v_odom = 1.03 * v + rng.normal(0, 0.02)
            w_odom = w + 0.02 + rng.normal(0, 0.01)
            oyaw = self.odom[2]
            self.odom += (v_odom * math.cos(oyaw) * dt, v_odom * math.sin(oyaw) * dt,
                          w_odom * dt)
            cov6 = np.diag([0.05**2, 0.01**2, 1e-6, 1e-6, 1e-6, 0.03**2])
            self.plugin.add_odometry("global_filter", "odom0", Odometry(
                header=Header(self.t, "odom"), child_frame_id="base_footprint",
                pose=Pose.from_xy_yaw(*self.odom),
                twist=Twist(vx=v_odom, wz=w_odom), twist_covariance=cov6))
            imu_yaw = self.true[2] + rng.normal(0, 0.02)
            self.plugin.add_imu("global_filter", "imu0", ImuPerception(
                orientation=np.array(yaw_to_quaternion(imu_yaw)),
                orientation_covariance=np.eye(3) * 0.02**2,
                angular_velocity=np.array((0.0, 0.0, w + 0.005 + rng.normal(0, 0.01))),
                angular_velocity_covariance=np.eye(3) * 0.01**2,
                linear_acceleration_covariance=-np.eye(3),
                stamp=self.t))
            in_outage = outage[0] <= self.t < outage[1]
            if k % GNSS_EVERY == 0 and not in_outage:
                fx = self.true[0] + rng.normal(0, GNSS_SIGMA)
                fy = self.true[1] + rng.normal(0, GNSS_SIGMA)
                if jump[0] <= self.t < jump[1]:
                    fx += 30.0
                fix_xy = (fx, fy)
                lat, lon = self.projection.inverse(fx, fy)
                self.nav_state.set("gps", GNSSPerception(
                    latitude=lat, longitude=lon, altitude=ORIGIN[2],
                    position_covariance=np.eye(3) * GNSS_SIGMA**2,
                    position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN,
                    status=STATUS_FIX, stamp=self.t))
                self.nav_state.add_to_group("gnss", "gps")
            self.plugin.update_rt(self.nav_state)
            if self.nav_state.has("robot_pose"):
                pose = self.nav_state.get("robot_pose", Odometry).pose
                self.log.append((self.t, *self.true[:2], pose.x, pose.y, *self.odom[:2],
                                 *fix_xy, self.true[2], pose.yaw))
        return np.array(self.log)


@pytest.fixture(scope="module")
def run() -> tuple[np.ndarray, Sim]:
    sim = Sim(fusion_params())
    return sim.run(), sim


def _errors(log: np.ndarray, cols: tuple[int, int]) -> np.ndarray:
    return np.hypot(log[:, cols[0]] - log[:, 1], log[:, cols[1]] - log[:, 2])


def test_fusion_beats_odometry_alone_and_gnss_alone(run):
    log, _ = run
    window = log[(log[:, 0] >= 5.0) & (log[:, 0] < OUTAGE[0])]  # after settling, before outage
    fused = np.sqrt(np.mean(_errors(window, (3, 4)) ** 2))
    odometry = np.sqrt(np.mean(_errors(window, (5, 6)) ** 2))
    gnss = np.sqrt(np.mean(_errors(window, (7, 8)) ** 2))
    assert fused < 0.5, fused
    assert fused < 0.5 * gnss, (fused, gnss)
    assert fused < odometry, (fused, odometry)
    # Over the whole run odometry alone drifts far more.
    assert np.sqrt(np.mean(_errors(log, (5, 6)) ** 2)) > 2.0


def test_gnss_outage_bridged_within_one_metre(run):
    log, _ = run
    outage = log[(log[:, 0] >= OUTAGE[0]) & (log[:, 0] < OUTAGE[1] + 5.0)]
    assert OUTAGE[1] - OUTAGE[0] >= 30.0
    assert _errors(outage, (3, 4)).max() < 1.0


def test_gnss_jump_rejected(run):
    log, sim = run
    after = log[(log[:, 0] >= JUMP[0]) & (log[:, 0] < JUMP[1] + 3.0)]
    assert _errors(after, (3, 4)).max() < 1.0
    assert sim.plugin.filters["global_filter"].rejected["gps0"] >= 5  # 10 jumped fixes (5 Hz, 2 s)
    yaw_error = np.abs((log[:, 9] - log[:, 10] + math.pi) % (2 * math.pi) - math.pi)
    assert yaw_error[log[:, 0] > 5.0].max() < 0.1


def test_without_gate_the_jump_pulls_the_estimate():
    params = fusion_params()
    del params["Ukf.global_filter.gps0_rejection_threshold"]
    log = Sim(params).run(duration=JUMP[1] + 1.0, outage=(0.0, 0.0))
    during = log[(log[:, 0] >= JUMP[0]) & (log[:, 0] < JUMP[1] + 1.0)]
    assert _errors(during, (3, 4)).max() > 3.0


def test_local_filter_writes_robot_pose_local():
    params = {
        "Ukf.local_filter.two_d_mode": True,
        # Known start pose, unknown velocities (an unknown yaw would shrink the expected advance).
        "Ukf.local_filter.initial_estimate_covariance": [1e-9] * 6 + [1.0] * 9,
        "Ukf.local_filter.odom0": "odom",
        "Ukf.local_filter.odom0_config": [False] * 6 + [True, False, False,
                                                        False, False, True] + [False] * 3,
    }
    context = PluginContext(parameters=DictParameters(params), namespace="fusion_local")
    plugin = FusionLocalizer()
    plugin.initialize(context, "Ukf")
    assert list(plugin.filters) == ["local_filter"]
    nav_state = NavState()
    for k in range(1, 41):  # 2 s at 1 m/s
        plugin.add_odometry("local_filter", "odom0", Odometry(
            header=Header(k * 0.05, "odom"), twist=Twist(vx=1.0),
            twist_covariance=np.eye(6) * 1e-4))
        plugin.update_rt(nav_state)
    pose = nav_state.get(ROBOT_POSE_LOCAL, Odometry)
    assert pose.pose.x == pytest.approx(1.95, abs=0.1)
    assert not nav_state.has("robot_pose")


def test_last_known_pose_moves_the_estimate_and_gnss_agrees(run):
    sim = Sim(fusion_params(), seed=3)
    sim.run(duration=10.0, outage=(0.0, 0.0))
    sim.plugin.on_last_known_pose(Odometry(
        header=Header(sim.t, "map"), pose=Pose.from_xy_yaw(100.0, 50.0, sim.true[2]),
        pose_covariance=np.eye(6) * 0.01))
    log = np.array(sim.run(duration=5.0, outage=(0.0, 0.0)))
    last = log[-1]
    # The estimate stays around the new pose: GNSS is shifted, not fighting it.
    moved = math.hypot(last[3] - last[1] - (100.0 - log[len(log) - 101][1]),
                       last[4] - last[2] - (50.0 - log[len(log) - 101][2]))
    assert moved < 5.0


def test_configuration_errors_name_the_parameter():
    context = PluginContext(parameters=DictParameters({}), namespace="fusion_none")
    with pytest.raises(PluginConfigurationError, match="global_filter"):
        FusionLocalizer().initialize(context, "Ukf")
    bad = fusion_params(**{"Ukf.global_filter.gps0_config": [True, True]})
    context = PluginContext(parameters=DictParameters(bad), namespace="fusion_bad")
    with pytest.raises(PluginConfigurationError, match="gps0_config"):
        FusionLocalizer().initialize(context, "Ukf")
    bad = fusion_params(**{"Ukf.global_filter.process_noise_covariance": [0.1] * 7})
    context = PluginContext(parameters=DictParameters(bad), namespace="fusion_bad2")
    with pytest.raises(PluginConfigurationError, match="process_noise_covariance"):
        FusionLocalizer().initialize(context, "Ukf")


def test_original_example_keys_are_known():
    keys = {
        "plugin": "easynav_fusion_localizer/FusionLocalizer",
        "rt_freq": 50.0, "freq": 5.0, "latitude_origin": 40.0,
        "global_filter.two_d_mode": True, "global_filter.map_frame": "map",
        "global_filter.gps0": "/gps/fix", "global_filter.gps0_config": [True] * 15,
        "global_filter.gps0_differential": False,
        "global_filter.gps0_relative": False,
        "global_filter.imu0_twist_rejection_threshold": 5.0,
        "global_filter.imu0_remove_gravitational_acceleration": True,
        "global_filter.twist0_config": [False] * 15,
        "global_filter.process_noise_covariance": [0.0] * 225,
    }
    unknown = FusionLocalizer.unknown_parameter_keys(keys)
    # The original's ukf_wrapper.cpp declares gpsN_differential/_relative and
    # imuN_twist_rejection_threshold; twistN has no _differential.
    assert unknown == []
    unknown = FusionLocalizer.unknown_parameter_keys({"global_filter.twist0_differential": True})
    assert [k for k, _ in unknown] == ["global_filter.twist0_differential"]


def test_ukf_transition_and_wrap():
    state = np.zeros(15)
    state[5], state[6], state[11] = math.pi - 0.01, 1.0, 1.0
    moved = transition(state, 0.1)
    assert moved[0] == pytest.approx(-0.1, abs=1e-3)
    assert moved[5] == pytest.approx(-math.pi + 0.09, abs=1e-9)  # wrapped
    ukf = UkfFilter(two_d_mode=True, initial_covariance=np.eye(15))
    assert ukf.correct([5], [math.pi - 0.05], [[0.01]])
    assert ukf.correct([5], [-math.pi + 0.05], [[0.01]])
    assert abs(abs(ukf.state[5]) - math.pi) < 0.1  # the mean of ±(π-0.05) is π, not 0
    assert not ukf.correct([0], [100.0], [[0.01]], threshold=3.0)
    assert ukf.state[0] == pytest.approx(0.0, abs=1e-6)


def test_batch_transition_matches_the_reference():
    rng = np.random.default_rng(1)
    states = rng.normal(0.0, 1.0, (31, 15))
    batch = transition_batch(states, 0.07)
    for row, moved in zip(states, batch, strict=False):
        np.testing.assert_allclose(moved, transition(row, 0.07), atol=1e-12)


def test_map_to_odom_uses_the_odometry_transform_at_the_estimates_time():
    """The filter's estimate is at the time of its last input; TF's odom -> robot may already
    be newer (the inputs queue while the RT loop is late). map -> odom is estimate ∘ (odom ->
    robot)⁻¹ at the estimate's time: with the newest transform it is off by what the robot
    drove in between (here 1 m)."""
    from easynav.common.tf import get_tf_buffer
    from easynav.core.types import Transform, TransformStamped

    params = {
        "Ukf.global_filter.two_d_mode": True,
        "Ukf.global_filter.publish_tf": True,
        "Ukf.global_filter.initial_estimate_covariance": [1e-9] * 6 + [1.0] * 9,
        "Ukf.global_filter.initial_state": [0.0] * 6 + [1.0] + [0.0] * 8,  # already driving
        "Ukf.global_filter.odom0": "odom",
        "Ukf.global_filter.odom0_config": [False] * 6 + [True, False, False,
                                                         False, False, True] + [False] * 3,
    }
    namespace = f"fusion_tf_{next(_namespaces)}"
    plugin = FusionLocalizer()
    plugin.initialize(PluginContext(parameters=DictParameters(params), namespace=namespace),
                      "Ukf")
    buffer = get_tf_buffer(namespace)

    def odom_tf(t: float) -> None:  # 1 m/s along x from the odom origin, there at t = 0.05
        buffer.set_transform(TransformStamped(
            Header(t, "odom"), "base_footprint",
            Transform(np.array((t - 0.05, 0.0, 0.0)), np.array((0.0, 0.0, 0.0, 1.0)))), "test")

    nav_state = NavState()
    for k in range(1, 41):  # 2 s of odometry, at 1 m/s
        t = k * 0.05
        odom_tf(t)
        plugin.add_odometry("global_filter", "odom0", Odometry(
            header=Header(t, "odom"), twist=Twist(vx=1.0), twist_covariance=np.eye(6) * 1e-4))
        plugin.update_rt(nav_state)
    for k in range(41, 61):  # TF runs 1 s ahead of the odometry the filter has fused
        odom_tf(k * 0.05)
    plugin.update_rt(nav_state)
    estimate = nav_state.get("robot_pose", Odometry)
    assert estimate.header.stamp == pytest.approx(2.0)
    _, (tx, ty, *_rest) = buffer.lookup_transform_values("map", "odom")
    # The map and odom frames start together: map -> odom is the estimate's small error, not
    # the 1 m driven after it.
    assert abs(tx) < 0.1 and abs(ty) < 0.1, (tx, ty)


def test_map_to_odom_when_the_odometry_transform_lags_the_estimate():
    """The converse: the filter's inputs (their own subscriptions) have run 0.4 s ahead of the
    ``odom -> robot`` transforms (the TF listener lags under load). The estimate is moved back
    to the newest transform's stamp at its own velocity before the two are composed; composed
    as they were, the robot stood 0.4 m ahead of itself on map -> odom -> robot."""
    from easynav.common.tf import TFBuffer
    from easynav.core.types import Transform, TransformStamped
    from easynav.localizers.map_to_odom import map_to_odom

    buffer = TFBuffer()
    for k in range(0, 41):  # odom -> robot up to t = 2.0: 1 m/s along odom's x, turning
        t = k * 0.05
        yaw = 0.2 * t
        buffer.set_transform(TransformStamped(
            Header(t, "odom"), "base_footprint",
            Transform(np.array((t, 0.0, 0.0)), np.array(yaw_to_quaternion(yaw)))), "test")
    # The true robot at t = 2.4 in the map frame (map = odom shifted by (5, 3)), estimated
    # exactly; its velocity in the body frame.
    stamp = 2.4
    true_then = (5.0 + 2.0, 3.0, 0.2 * 2.0)  # map pose at t = 2.0, where TF's latest is
    estimate_x = true_then[0] + 0.4 * math.cos(0.44)  # moved on 0.4 s at 1 m/s, mid-yaw 0.44
    estimate_y = true_then[1] + 0.4 * math.sin(0.44)
    transform = map_to_odom(buffer, estimate_x, estimate_y, 0.2 * 2.4, stamp,
                            twist=(1.0, 0.0, 0.2))
    assert transform.header.stamp == stamp
    np.testing.assert_allclose(transform.transform.translation[:2], (5.0, 3.0), atol=1e-3)
    without = map_to_odom(buffer, estimate_x, estimate_y, 0.2 * 2.4, stamp)
    assert math.hypot(*(without.transform.translation[:2] - (5.0, 3.0))) > 0.35


def _turning_odometry(buffer, until: float, start: float = 0.0) -> None:
    """odom -> robot every 0.02 s over [start, until]: 0.5 m/s forward, turning at 0.3 rad/s
    from the odom origin, as (x, y, yaw) of t: exact arcs."""
    for k in range(round(start / 0.02), round(until / 0.02) + 1):
        buffer.set_transform_values("odom", "base_footprint", k * 0.02,
                                    (*_arc(k * 0.02)[:2], 0.0,
                                     *yaw_to_quaternion(_arc(k * 0.02)[2])), "test")


def _arc(t: float) -> tuple[float, float, float]:
    v, w = 0.5, 0.3
    return v / w * math.sin(w * t), v / w * (1.0 - math.cos(w * t)), w * t


def test_carry_pose_moves_a_pose_by_the_odometry_since_its_stamp():
    """A pose of t = 1 carried to t = 2.5 by the odom -> robot transforms in between lands
    where the robot is then; without transforms, the twist moves it (constant velocity), and
    without either it stays. Map and odom differ by a rotation and a shift."""
    from easynav.common.tf import TFBuffer
    from easynav.localizers.map_to_odom import carry_pose

    buffer = TFBuffer()
    _turning_odometry(buffer, 3.0)
    shift, turn = np.array((4.0, -2.0)), 0.7  # map -> odom

    def in_map(pose):
        c, s = math.cos(turn), math.sin(turn)
        return (shift[0] + c * pose[0] - s * pose[1], shift[1] + s * pose[0] + c * pose[1],
                pose[2] + turn)

    then, now = in_map(_arc(1.0)), in_map(_arc(2.5))
    carried = carry_pose(buffer, *then, 1.0, 2.5)
    np.testing.assert_allclose(carried, now, atol=1e-6)
    # Beyond the newest transform (t = 3): odometry to 3, then the twist for the rest.
    later = in_map(_arc(3.4))
    carried = carry_pose(buffer, *then, 1.0, 3.4, twist=(0.5, 0.0, 0.3))
    np.testing.assert_allclose(carried[:2], later[:2], atol=2e-3)
    # No odometry transforms: the twist alone (the arc's chord at the middle heading), for
    # one second at most (the robot may have braked meanwhile).
    empty = TFBuffer()
    carried = carry_pose(empty, *then, 1.0, 1.8, twist=(0.5, 0.0, 0.3))
    np.testing.assert_allclose(carried, in_map(_arc(1.8)), atol=1e-2)  # chord vs arc: 2 mm
    carried = carry_pose(empty, *then, 1.0, 2.5, twist=(0.5, 0.0, 0.3))
    np.testing.assert_allclose(carried, in_map(_arc(2.0)), atol=1e-2)
    assert carry_pose(empty, *then, 1.0, 2.5) == then
    # Unstamped (0) or not older than ``until``: unchanged.
    assert carry_pose(buffer, *then, 0.0, 2.5) == then
    assert carry_pose(buffer, *then, 2.5, 2.5) == then


def _odometry_fusion(clock: dict, publish_tf: bool) -> tuple[FusionLocalizer, str]:
    """A FusionLocalizer whose global filter fuses the odometry's vx and vyaw only, on the
    clock ``clock["t"]``, in a TF namespace of its own (returned)."""
    params = {
        "Ukf.global_filter.two_d_mode": True,
        "Ukf.global_filter.publish_tf": publish_tf,
        "Ukf.global_filter.odom0": "odom",
        "Ukf.global_filter.odom0_config": [False] * 6 + [True, False, False,
                                                         False, False, True] + [False] * 3,
    }
    namespace = f"fusion_odometry_{next(_namespaces)}"
    plugin = FusionLocalizer()
    plugin.initialize(PluginContext(parameters=DictParameters(params), namespace=namespace,
                                    now=lambda: clock["t"]), "Ukf")
    return plugin, namespace


def test_a_handed_over_pose_is_carried_to_the_first_measurement():
    """A localizer swap: the previous localizer's last pose is stamped when it last ran
    (t = 1.0); the fusion localizer starts fusing 1.5 s later, with odometry messages from
    t = 2.5 only (the older ones fell out of its queue during the reconfiguration), while
    the robot drove on. The estimate starts where the robot is at t = 2.5, not where it was
    at t = 1.0 (0.75 m behind, for the rest of a mission on odometry alone)."""
    from easynav.common.tf import get_tf_buffer

    clock = {"t": 1.0}
    plugin, namespace = _odometry_fusion(clock, publish_tf=True)
    buffer = get_tf_buffer(namespace)
    _turning_odometry(buffer, 2.5)
    # Map and odom coincide: the previous localizer's pose at t = 1 is the arc's.
    x, y, yaw = _arc(1.0)
    plugin.on_last_known_pose(Odometry(
        header=Header(1.0, "map"), pose=Pose.from_xy_yaw(x, y, yaw),
        pose_covariance=np.eye(6) * 1e-4, twist=Twist(vx=0.5, wz=0.3)))
    nav_state = NavState()
    for k in range(125, 151):  # t = 2.5 .. 3.0: odometry messages and transforms
        t = k * 0.02
        clock["t"] = t
        _turning_odometry(buffer, t, start=t)
        plugin.add_odometry("global_filter", "odom0", Odometry(
            header=Header(t, "odom"), twist=Twist(vx=0.5, wz=0.3),
            twist_covariance=np.eye(6) * 1e-6))
        plugin.update_rt(nav_state)
    estimate = nav_state.get("robot_pose", Odometry)
    assert estimate.header.stamp == pytest.approx(3.0)
    truth = _arc(3.0)
    assert math.hypot(estimate.pose.x - truth[0], estimate.pose.y - truth[1]) < 0.01
    assert abs(estimate.pose.yaw - truth[2]) < 0.01


def test_a_pose_stamped_on_another_clock_is_taken_as_of_now():
    """An initialpose from a tool on wall time (1.7e9 s) while the robot runs on simulated
    time (t = 2): the pose is applied as of the next measurement. Taken at its stamp, it moved
    the filter's clock to 1.7e9 and every later measurement was "late": the estimate stood."""
    clock = {"t": 0.0}
    plugin, _ = _odometry_fusion(clock, publish_tf=False)
    nav_state = NavState()

    def drive(start: int, end: int) -> None:  # 1 m/s along x, 50 Hz
        for k in range(start, end):
            clock["t"] = k * 0.02
            plugin.add_odometry("global_filter", "odom0", Odometry(
                header=Header(clock["t"], "odom"), twist=Twist(vx=1.0),
                twist_covariance=np.eye(6) * 1e-6))
            plugin.update_rt(nav_state)

    drive(1, 100)
    plugin.on_last_known_pose(Odometry(header=Header(1.7e9, "map"),
                                       pose=Pose.from_xy_yaw(10.0, 0.0, 0.0),
                                       pose_covariance=np.eye(6) * 1e-4))
    drive(100, 201)  # 2 s more at 1 m/s
    estimate = nav_state.get("robot_pose", Odometry)
    assert estimate.header.stamp == pytest.approx(4.0)
    assert estimate.pose.x == pytest.approx(12.0, abs=0.1)  # (not 10: it stood)


def test_map_to_odom_takes_the_estimate_of_the_transforms_time_from_the_history():
    """TF's newest odom -> robot is 0.9 s behind the estimate (the TF listener's queue lags
    the odometry subscription under load) and the filter's velocity is noisy (0.2 m/s here,
    against 0.3): moved back by it, map -> odom was 0.09 m off. The estimate the filter had
    at the transform's time, from its history, is exact."""
    from easynav.common.tf import TFBuffer
    from easynav.core.types import Transform, TransformStamped
    from easynav.localizers.map_to_odom import PoseHistory, map_to_odom

    buffer = TFBuffer()
    history = PoseHistory()
    shift = (5.0, 3.0)  # map = odom shifted
    for k in range(0, 101):  # 0.3 m/s along x, odom -> robot up to t = 1.1 only
        t = k * 0.02
        if t <= 1.1 + 1e-9:
            buffer.set_transform(TransformStamped(
                Header(t, "odom"), "base_footprint",
                Transform(np.array((0.3 * t, 0.0, 0.0)), np.array((0.0, 0.0, 0.0, 1.0)))),
                "test")
        history.add(t, shift[0] + 0.3 * t, shift[1], 0.0)
    stamp = 2.0
    estimate = (shift[0] + 0.3 * stamp, shift[1], 0.0)
    with_history = map_to_odom(buffer, *estimate, stamp, twist=(0.2, 0.0, 0.0),
                               history=history)
    np.testing.assert_allclose(with_history.transform.translation[:2], shift, atol=1e-9)
    twist_only = map_to_odom(buffer, *estimate, stamp, twist=(0.2, 0.0, 0.0))
    assert abs(twist_only.transform.translation[0] - shift[0]) > 0.08


def test_pose_history_interpolates_within_its_span():
    from easynav.localizers.map_to_odom import PoseHistory

    history = PoseHistory(span=1.0)
    history.add(0.0, 0.0, 0.0, math.pi - 0.1)
    history.add(1.0, 1.0, 2.0, -math.pi + 0.1)  # across ±π
    history.add(0.5, 9.0, 9.0, 0.0)  # older than the last: ignored
    x, y, yaw = history.at(0.5)
    assert (x, y) == pytest.approx((0.5, 1.0)) and abs(abs(yaw) - math.pi) < 1e-9
    assert history.at(-0.1) is None and history.at(1.1) is None
    history.add(2.5, 3.0, 3.0, 0.0)  # the span drops what is older than 1 s
    assert history.at(1.0) is None and history.at(2.5) == (3.0, 3.0, 0.0)
    history.clear()
    assert history.at(2.5) is None


def test_a_late_fix_does_not_pull_the_estimate_back():
    """A fix that arrives after odometry has carried the estimate past its stamp (the sensors
    node runs apart from the RT loop) is where the robot *was*: moved on by the estimated
    motion since, it agrees with the estimate; fused as it is, it pulled the estimate back."""
    sim = Sim(fusion_params(**{"Ukf.global_filter.gps0_rejection_threshold": 1e9}), seed=5)
    projection = sim.projection
    plugin, nav_state = sim.plugin, sim.nav_state
    dt = 1.0 / RATE
    t = 0.0
    for k in range(int(20.0 * RATE)):  # straight along x at 1 m/s, exact sensors
        t = (k + 1) * dt
        plugin.add_odometry("global_filter", "odom0", Odometry(
            header=Header(t, "odom"), pose=Pose.from_xy_yaw(t, 0.0, 0.0),
            twist=Twist(vx=1.0), twist_covariance=np.eye(6) * 1e-4))
        plugin.add_imu("global_filter", "imu0", ImuPerception(
            orientation=np.array(yaw_to_quaternion(0.0)), orientation_covariance=np.eye(3) * 1e-4,
            angular_velocity=np.zeros(3), angular_velocity_covariance=np.eye(3) * 1e-4,
            linear_acceleration_covariance=-np.eye(3), stamp=t))
        if k % GNSS_EVERY == 0:
            lat, lon = projection.inverse(t, 0.0)
            nav_state.set("gps", GNSSPerception(
                latitude=lat, longitude=lon, altitude=ORIGIN[2],
                position_covariance=np.eye(3) * 0.15**2,
                position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN,
                status=STATUS_FIX, stamp=t))
            nav_state.add_to_group("gnss", "gps")
        plugin.update_rt(nav_state)
    before = nav_state.get("robot_pose", Odometry).pose.x
    assert before == pytest.approx(t, abs=0.1)
    late = t - 0.8  # where the robot was 0.8 s ago, delivered now
    lat, lon = projection.inverse(late, 0.0)
    nav_state.set("gps", GNSSPerception(
        latitude=lat, longitude=lon, altitude=ORIGIN[2], position_covariance=np.eye(3) * 0.15**2,
        position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN, status=STATUS_FIX, stamp=late))
    plugin.update_rt(nav_state)
    after = nav_state.get("robot_pose", Odometry).pose.x
    assert after == pytest.approx(before, abs=0.05), (before, after)
