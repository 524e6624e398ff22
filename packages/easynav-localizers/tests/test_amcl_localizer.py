"""AMCLLocalizer without ROS: convergence on a known map from simulated scans, TF, resets."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.types import Header, Odometry, Pose, Transform, TransformStamped, Twist
from easynav.localizers.amcl_localizer import (
    AMCLLocalizer,
    moved_by_increment,
    odometry_increment,
)
from easynav.maps import SimpleMap, resolve_map_file

_namespaces = itertools.count()
LASER_Z = 0.25


def ray_cast(world: SimpleMap, pose, beams: int, max_range: float, rng, noise=0.01):
    """Laser points (laser frame, z 0) of a 360° scanner at ``pose`` on ``world``."""
    angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
    r = np.arange(0.0, max_range, world.resolution / 2)
    a = angles[:, None] + pose[2]
    occupied = world.occupied_at(pose[0] + r * np.cos(a), pose[1] + r * np.sin(a), outside=True)
    hit = occupied.any(axis=1)
    ranges = r[occupied.argmax(axis=1)][hit] + rng.normal(0.0, noise, hit.sum())
    return np.column_stack(
        (ranges * np.cos(angles[hit]), ranges * np.sin(angles[hit]), np.zeros(hit.sum()))
    )


class Sim:
    """A unicycle on the house map with drifting odometry, a laser and a clock."""

    def __init__(self, params: dict, start=(0.0, 0.0, 0.0), seed=0) -> None:
        self.rng = np.random.default_rng(seed)
        self.world = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
        self.t = 10.0
        self.true = np.array(start, dtype=float)
        self.odom = np.zeros(3)  # odometry starts at zero wherever the robot is
        namespace = f"amcl_test_{next(_namespaces)}"
        buffer = get_tf_buffer(namespace)
        buffer.set_transform(
            TransformStamped(
                Header(0.0, "base_footprint"),
                "base_laser",
                Transform(np.array([0.1, 0.0, LASER_Z]), np.array([0.0, 0.0, 0.0, 1.0])),
            ),
            "test",
            is_static=True,
        )
        context = PluginContext(
            parameters=DictParameters({f"simple.{k}": v for k, v in params.items()}),
            namespace=namespace,
            now=lambda: self.t,
        )
        self.amcl = AMCLLocalizer()
        self.amcl.initialize(context, "simple")
        self.amcl.filter.rng = np.random.default_rng(seed + 100)
        self.nav_state = NavState()
        self.nav_state.set("map.base", self.world)
        self.buffer = buffer

    def step(self, v: float, w: float, dt: float, correct: bool) -> None:
        # True motion, and odometry that drifts 2 % in distance and 3 % in rotation.
        yaw = self.true[2]
        self.true += (v * math.cos(yaw) * dt, v * math.sin(yaw) * dt, w * dt)
        oyaw = self.odom[2]
        self.odom += (
            1.02 * v * math.cos(oyaw) * dt,
            1.02 * v * math.sin(oyaw) * dt,
            1.03 * w * dt,
        )
        self.t += dt
        self.amcl.set_odometry(
            Odometry(
                Header(self.t, "odom"),
                "base_footprint",
                Pose.from_xy_yaw(*self.odom),
                twist=Twist(vx=v, wz=w),
            )
        )
        self.amcl.update_rt(self.nav_state)
        if correct:
            # The laser sits 0.1 m ahead of the footprint.
            c, s = math.cos(self.true[2]), math.sin(self.true[2])
            laser = (self.true[0] + 0.1 * c, self.true[1] + 0.1 * s, self.true[2])
            points = ray_cast(self.world, laser, 180, 6.0, self.rng)
            points[:, 2] = 0.0
            self.nav_state.set("laser1", PointPerception(points, "base_laser", self.t))
            self.amcl.update(self.nav_state)

    def error(self) -> tuple[float, float]:
        pose = self.nav_state.get("robot_pose", Odometry).pose
        yaw_error = math.remainder(pose.yaw - self.true[2], 2 * math.pi)
        return math.hypot(pose.x - self.true[0], pose.y - self.true[1]), abs(yaw_error)


SEED_PARAMS = {
    "rt_freq": 50.0,
    "freq": 5.0,
    "reseed_freq": 1.0,
    "num_particles": 100,
    "noise_translation": 0.05,
    "noise_rotation": 0.1,
    "noise_translation_to_rotation": 0.1,
}


@pytest.mark.parametrize("seed", range(3))
def test_converges_from_a_spread_initial_pose_while_driving(seed):
    params = dict(SEED_PARAMS)
    # The belief is centred 0.4 m and 0.25 rad off the truth, and wide.
    params.update(
        {
            "initial_pose.x": 0.3,
            "initial_pose.y": -0.25,
            "initial_pose.yaw": 0.25,
            "initial_pose.std_dev_xy": 0.5,
            "initial_pose.std_dev_yaw": 0.3,
        }
    )
    sim = Sim(params, seed=seed)
    first_trace = (
        sim.nav_state.get("localizer.amcl.covariance_trace", float)
        if sim.nav_state.has("localizer.amcl.covariance_trace")
        else None
    )
    dt = 0.02
    errors = []
    for i in range(int(12.0 / dt)):  # 12 s: RT at 50 Hz, correction at 5 Hz
        w = 0.3 * math.sin(i * dt * 0.8)
        sim.step(0.3, w, dt, correct=(i % 10 == 0))
        errors.append(sim.error())
    xy_error, yaw_error = sim.error()
    assert xy_error < 0.1, errors[::50]
    assert yaw_error < 0.05
    assert max(e[0] for e in errors[-100:]) < 0.15  # it stays converged
    trace = sim.nav_state.get("localizer.amcl.covariance_trace", float)
    assert trace < 0.05
    assert first_trace is None or trace < first_trace


def test_robot_pose_stamp_frames_and_map_to_odom():
    sim = Sim(
        dict(SEED_PARAMS, **{"initial_pose.std_dev_xy": 0.01, "initial_pose.std_dev_yaw": 0.01}),
        start=(0.0, 0.0, 0.0),
    )
    for i in range(50):
        sim.step(0.2, 0.1, 0.02, correct=(i % 10 == 0))
    pose = sim.nav_state.get("robot_pose", Odometry)
    assert pose.header.frame_id == "map" and pose.child_frame_id == "base_footprint"
    assert pose.header.stamp == pytest.approx(sim.t)  # the stamp of the odometry used
    assert pose.twist.vx == 0.2
    assert pose.pose_covariance[0, 0] > 0.0 and pose.pose_covariance[5, 5] > 0.0
    # map→odom ∘ odom→base_footprint = the estimate.
    tf = sim.buffer.lookup_transform("map", "odom")
    yaw_mo = Pose(qz=tf.transform.rotation[2], qw=tf.transform.rotation[3]).yaw
    ox, oy, oyaw = sim.odom
    c, s = math.cos(yaw_mo), math.sin(yaw_mo)
    x = tf.transform.translation[0] + c * ox - s * oy
    y = tf.transform.translation[1] + s * ox + c * oy
    assert (x, y) == pytest.approx((pose.pose.x, pose.pose.y), abs=1e-9)
    assert math.remainder(yaw_mo + oyaw - pose.pose.yaw, 2 * math.pi) == pytest.approx(0, abs=1e-9)


def test_reset_pose_and_last_known_pose_move_the_cloud():
    sim = Sim(SEED_PARAMS)
    sim.amcl.reset_pose(3.0, 2.0, 1.0, np.eye(2) * 0.01, 0.0001)
    assert sim.amcl.filter.poses[:, :2].mean(axis=0) == pytest.approx([3.0, 2.0], abs=0.05)
    # Yaw std at least min_noise_yaw (0.05) even though 0.01 rad was asked.
    assert sim.amcl.filter.poses[:, 2].std() > 0.03
    last = Odometry(Header(1.0, "map"), "base_footprint", Pose.from_xy_yaw(-1.0, 1.0, 0.5))
    sim.amcl.on_last_known_pose(last)
    assert sim.amcl.filter.estimate() == pytest.approx((-1.0, 1.0, 0.5), abs=0.05)


def test_without_map_or_perceptions_it_predicts_only():
    sim = Sim(SEED_PARAMS)
    sim.nav_state.erase("map.base")
    sim.step(0.1, 0.0, 0.1, correct=True)
    assert sim.nav_state.has("robot_pose")


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"num_particles": 0}, "simple.num_particles = 0: must be >= 1"),
        ({"num_particles": 2.5}, "simple.num_particles = 2.5: must be an integer"),
        ({"reseed_freq": 0.0}, "simple.reseed_freq = 0.0: must be > 0"),
        ({"noise_rotation": -0.1}, "simple.noise_rotation = -0.1: must be >= 0"),
        ({"initial_pose.x": "here"}, "simple.initial_pose.x = 'here': must be a number"),
    ],
)
def test_bad_parameters_fail_configuration(params, message):
    with pytest.raises(PluginConfigurationError, match=message):
        Sim(params)


def test_scores_in_numpy_at_the_simple_stacks_size_and_compiled_beyond(monkeypatch):
    # 200 particles × up to 360 scan points (the simple stack's playground params) do not load
    # numba for the scoring alone (about 100 MB resident, issue #21); a large cloud does.
    import easynav.localizers.particle_filter as pf

    assert not pf.compiled_scoring_pays(200, 360)
    assert pf.compiled_scoring_pays(2000, 360)
    calls = []
    real = pf.hit_fractions

    def spy(poses, points_xy, grid, field=None, chunk=128, compiled=True):
        calls.append((len(poses), compiled))
        return real(poses, points_xy, grid, field, chunk, compiled)

    monkeypatch.setattr("easynav.localizers.amcl_localizer.hit_fractions", spy)
    for particles in (200, 2000):
        sim = Sim(dict(SEED_PARAMS, num_particles=particles))
        sim.step(0.0, 0.0, 0.02, correct=True)
    assert calls == [(200, False), (2000, True)]


def test_a_pose_moved_by_the_increment_between_two_odometries_lands_on_the_second():
    rng = np.random.default_rng(4)
    for _ in range(50):
        a, b = rng.uniform((-5, -5, -math.pi), (5, 5, math.pi), (2, 3))
        moved = moved_by_increment(a, odometry_increment(tuple(a), tuple(b)))[0]
        assert np.allclose(moved[:2], b[:2])
        assert abs((moved[2] - b[2] + math.pi) % (2 * math.pi) - math.pi) < 1e-9
    # A robot 1 m along x, facing +y, that drove 1 m forward and turned a quarter: (1, 1, -π)
    # (headings in [-π, π), as normalize_angle's).
    assert np.allclose(moved_by_increment(np.array([[1.0, 0.0, math.pi / 2]]),
                                          (1.0, 0.0, math.pi / 2)), [[1.0, 1.0, -math.pi]])
