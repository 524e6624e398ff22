"""The NavMap AMCL without ROS: a room on two levels joined by a ramp (the ground floor runs
under the upper one), a NavMap of its walkable surfaces and a Bonxai map of its solids;
simulated 3D scans ray-cast against the voxels."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.common.sensors import ImuPerception, PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.types import Header, Odometry, Pose, Transform, TransformStamped
from easynav.core.types.quaternion import quaternion_to_matrix
from easynav.localizers import navmap_amcl_localizer as module
from easynav.localizers.navmap_amcl_localizer import NavMapAMCLLocalizer, attitudes
from easynav.localizers.navmap_voxel_scoring import (
    InflatedVoxelMap,
    point_scores,
    ray_occluded_reference,
    rays_occluded,
    score_particles,
    score_reference,
)
from easynav.maps.navmap import NavMap
from easynav.maps.voxel import BonxaiMap

_namespaces = itertools.count()
RES = 0.1
SLOPE = math.atan2(1.5, 4.0)  # the ramp rises 1.5 m over 4 m


# -- the world ---------------------------------------------------------------------------------
def ramp_z(x):
    return 1.5 * (np.asarray(x, dtype=float) - 1.0) / 4.0


def _quads(x0, x1, y0, y1, zf, step=0.25):
    xs = np.linspace(x0, x1, round((x1 - x0) / step) + 1)
    ys = np.linspace(y0, y1, round((y1 - y0) / step) + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    vertices = np.column_stack((gx.ravel(), gy.ravel(), zf(gx.ravel(), gy.ravel())))
    ny = len(ys)
    faces = []
    for i in range(len(xs) - 1):
        for j in range(ny - 1):
            a, b, c, d = i * ny + j, (i + 1) * ny + j, (i + 1) * ny + j + 1, i * ny + j + 1
            faces += [(a, b, c), (a, c, d)]
    return vertices, np.array(faces)


def two_level_navmap() -> NavMap:
    """Ground floor (z 0) of a 10 × 6 m room but under the ramp; the ramp [1, 5] × [4, 6]
    rising along +x to the upper floor [5, 10] × [2, 6] at z 1.5, above the ground floor."""
    def flat(z):
        return lambda x, y: np.full(len(x), z)

    pieces = [
        (0.0, 1.0, 0.0, 6.0, flat(0.0)), (1.0, 5.0, 0.0, 4.0, flat(0.0)),
        (5.0, 10.0, 0.0, 6.0, flat(0.0)), (1.0, 5.0, 4.0, 6.0, lambda x, y: ramp_z(x)),
        (5.0, 10.0, 2.0, 6.0, flat(1.5)),
    ]
    vertices, faces = [], []
    offset = 0
    for piece in pieces:
        v, f = _quads(*piece)
        vertices.append(v)
        faces.append(f + offset)
        offset += len(v)
    return NavMap(np.concatenate(vertices), np.concatenate(faces))


def _box(x0, x1, y0, y1, z0, z1):
    c = [np.arange(a + RES / 2, b, RES) for a, b in ((x0, x1), (y0, y1), (z0, z1))]
    g = np.meshgrid(*c, indexing="ij")
    return np.column_stack([a.ravel() for a in g])


def two_level_voxels() -> BonxaiMap:
    """The solids: outer walls, both slabs, the ramp's wedge and wall, furniture."""
    boxes = [
        (0.0, 0.1, 0.0, 6.0, 0.0, 3.0), (9.9, 10.0, 0.0, 6.0, 0.0, 3.0),
        (0.0, 10.0, 0.0, 0.1, 0.0, 3.0), (0.0, 10.0, 5.9, 6.0, 0.0, 3.0),
        (0.0, 10.0, 0.0, 6.0, -0.1, 0.0),  # ground slab
        (5.0, 10.0, 2.0, 6.0, 1.3, 1.5),  # upper floor slab
        (1.0, 5.0, 3.9, 4.0, 0.0, 1.0),  # the ramp's side wall
        (2.3, 2.6, 1.3, 1.6, 0.0, 2.5),  # a pillar on the ground floor
        (7.6, 8.4, 4.6, 5.4, 1.5, 2.3),  # a box on the upper floor
        (6.5, 7.3, 2.5, 3.3, 0.0, 0.8),  # a box under the upper floor
        (5.0, 10.0, 1.9, 2.0, 1.5, 2.4),  # the upper floor's railing
    ]
    points = [_box(*b) for b in boxes]
    x = np.arange(1.0 + RES / 2, 5.0, RES)  # the ramp's wedge, up to its surface
    for xi in x:
        points.append(_box(xi - RES / 2, xi + RES / 2, 4.0, 6.0, 0.0, float(ramp_z(xi))))
    voxels = BonxaiMap(RES)
    voxels.set_occupied(np.concatenate(points))
    return voxels


def ray_cast(voxels: BonxaiMap, origin, yaw, rng, max_range=8.0, noise=0.01) -> np.ndarray:
    """Points (sensor frame, level sensor) of a 3D lidar at ``origin``: 60 azimuths × 7
    elevations, marched in 2.5 cm steps until an occupied voxel."""
    az = np.radians(np.arange(0.0, 360.0, 6.0))
    el = np.radians([-30.0, -15.0, -5.0, 5.0, 15.0, 30.0, 50.0])
    a, e = np.meshgrid(az, el, indexing="ij")
    d = np.column_stack((np.cos(e.ravel()) * np.cos(a.ravel()),
                         np.cos(e.ravel()) * np.sin(a.ravel()), np.sin(e.ravel())))
    c, s = math.cos(yaw), math.sin(yaw)
    world = d @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    r = np.arange(0.05, max_range, RES / 4)
    samples = np.asarray(origin)[None, None, :] + world[:, None, :] * r[None, :, None]
    occupied = voxels.is_occupied(samples.reshape(-1, 3)).reshape(len(d), len(r))
    hit = occupied.any(axis=1)
    ranges = r[occupied.argmax(axis=1)][hit] + rng.normal(0.0, noise, hit.sum())
    return d[hit] * ranges[:, None]


def rotation_of(pose: Pose) -> np.ndarray:
    return quaternion_to_matrix(np.array((pose.qx, pose.qy, pose.qz, pose.qw)))


class Recorder:
    """A logger that keeps the messages."""

    def __init__(self) -> None:
        self.messages: list[tuple[str, str]] = []

    def _log(self, level, msg, *args, **kwargs):
        self.messages.append((level, str(msg)))

    def debug(self, msg, *a, **k):
        self._log("debug", msg)

    def info(self, msg, *a, **k):
        self._log("info", msg)

    def warning(self, msg, *a, **k):
        self._log("warning", msg)

    warn = warning

    def error(self, msg, *a, **k):
        self._log("error", msg)

    def text(self, level="warning") -> str:
        return "\n".join(m for lv, m in self.messages if lv == level)


NAVMAP = two_level_navmap()
VOXELS = two_level_voxels()
SENSOR_HEIGHT = 0.3


class Sim:
    """The localizer in a namespace of its own, a lidar 0.3 m above the footprint, a clock."""

    def __init__(self, params: dict, seed=0, maps=True) -> None:
        self.rng = np.random.default_rng(seed)
        self.t = 10.0
        self.odom = np.zeros(3)
        namespace = f"navmap_amcl_test_{next(_namespaces)}"
        self.buffer = get_tf_buffer(namespace)
        self.buffer.set_transform(
            TransformStamped(Header(0.0, "base_footprint"), "lidar",
                             Transform(np.array([0.0, 0.0, SENSOR_HEIGHT]))),
            "test", is_static=True,
        )
        self.log = Recorder()
        context = PluginContext(
            parameters=DictParameters({f"amcl.{k}": v for k, v in params.items()}),
            namespace=namespace, now=lambda: self.t, logger=self.log,
        )
        self.amcl = NavMapAMCLLocalizer()
        self.amcl.initialize(context, "amcl")
        self.amcl.filter.rng = np.random.default_rng(seed + 100)
        p = self.amcl.params
        self.amcl.filter.seed(p["initial_pose.x"], p["initial_pose.y"], p["initial_pose.yaw"],
                              np.eye(2) * p["initial_pose.std_dev_xy"] ** 2,
                              p["initial_pose.std_dev_yaw"])
        self.nav_state = NavState()
        if maps:
            self.nav_state.set("map.navmap", NAVMAP)
            self.nav_state.set("map.bonxai", VOXELS)

    def move(self, forward: float, dyaw: float = 0.0, dt: float = 0.1) -> None:
        """Odometry advances by ``forward`` m and ``dyaw`` rad (robot frame)."""
        yaw = self.odom[2]
        self.odom += (forward * math.cos(yaw), forward * math.sin(yaw), dyaw)
        self.t += dt
        self.amcl.set_odometry(Odometry(Header(self.t, "odom"), "base_footprint",
                                        Pose.from_xy_yaw(*self.odom)))
        self.amcl.update_rt(self.nav_state)

    def scan(self, true_pose) -> None:
        x, y, z, yaw = true_pose
        points = ray_cast(VOXELS, (x, y, z + SENSOR_HEIGHT), yaw, self.rng)
        self.nav_state.set("lidar", PointPerception(points, "lidar", self.t))
        self.amcl.update(self.nav_state)

    def pose(self) -> Pose:
        return self.nav_state.get("robot_pose", Odometry).pose


# -- scoring -----------------------------------------------------------------------------------
def wall_map() -> BonxaiMap:
    """Two walls across x: at x 2.0-2.1 and at x 4.0-4.1 (y, z in [-1, 1])."""
    voxels = BonxaiMap(RES)
    voxels.set_occupied(np.concatenate([_box(2.0, 2.1, -1, 1, -1, 1),
                                        _box(4.0, 4.1, -1, 1, -1, 1)]))
    return voxels


def test_inflated_map_probabilities():
    inflated = InflatedVoxelMap(wall_map(), 0.1, 0.01)
    p = inflated.probability_at(np.array([[2.05, 0.05, 0.05], [2.15, 0.05, 0.05],
                                          [2.25, 0.05, 0.05], [3.0, 0.05, 0.05]]))
    assert p[0] == 1.0
    assert p[1] == pytest.approx(math.exp(-0.5), abs=0.005)  # one voxel (0.1 m) away
    assert p[2] == pytest.approx(math.exp(-2.0), abs=0.005)
    assert p[3] == 0.0
    assert inflated.tail_skip == math.ceil(0.1 * math.sqrt(-2 * math.log(0.01)) / RES)


def test_occluded_points_score_zero():
    inflated = InflatedVoxelMap(wall_map(), 0.05, 0.01)
    origin = np.array([[0.55, 0.05, 0.05]])
    ends = np.array([[2.05, 0.05, 0.05],   # on the first wall: seen
                     [4.05, 0.05, 0.05],   # on the second wall, behind the first: occluded
                     [4.05, 0.05, 1.95],   # above the first wall (z 1.95): not on a wall
                     [3.0, 0.05, 0.05]])   # free space between the walls: 0
    scores = point_scores(inflated, np.repeat(origin, 4, axis=0), ends)
    assert scores.tolist() == [1.0, 0.0, 0.0, 0.0]
    # From between the walls the second one is seen, the first one (behind) is not.
    scores = point_scores(inflated, np.full((2, 3), (3.05, 0.05, 0.05)),
                          np.array([[4.05, 0.05, 0.05], [2.05, 0.05, 0.05]]))
    assert scores.tolist() == [1.0, 1.0]  # nothing between: both visible
    scores = point_scores(inflated, np.full((1, 3), (5.05, 0.05, 0.05)),
                          np.array([[2.05, 0.05, 0.05]]))
    assert scores.tolist() == [0.0]


def test_closed_form_rays_match_the_original_dda():
    inflated = InflatedVoxelMap(VOXELS, 0.05, 0.01)
    rng = np.random.default_rng(1)
    a = rng.integers(-5, 105, (3000, 3)) * np.array([1, 1, 1]) // np.array([1, 1, 3])
    b = rng.integers(-5, 105, (3000, 3)) // np.array([1, 1, 3])
    for skip in (0, 1, 3):
        fast = rays_occluded(inflated, a, b, skip)
        slow = [ray_occluded_reference(inflated, p, q, skip) for p, q in zip(a, b, strict=True)]
        assert fast.tolist() == slow
    assert 0 < fast.sum() < len(a)


def test_vectorised_scores_match_the_per_particle_loop():
    inflated = InflatedVoxelMap(VOXELS, 0.1, 0.01)
    rng = np.random.default_rng(2)
    points = ray_cast(VOXELS, (3.0, 2.0, 0.3), 0.0, rng)[::7] + (0.0, 0.0, 0.3)
    origins = np.tile((0.0, 0.0, 0.3), (len(points), 1))
    yaws = rng.normal(0.0, 0.2, 6)
    normals = np.tile((0.0, 0.0, 1.0), (6, 1))
    rot = attitudes(yaws, normals)
    trans = np.column_stack((3.0 + rng.normal(0, 0.2, 6), 2.0 + rng.normal(0, 0.2, 6),
                             np.zeros(6)))
    fast = score_particles(inflated, rot, trans, points, origins, chunk=4, compiled=False)
    slow = score_reference(inflated, rot, trans, points, origins)
    np.testing.assert_allclose(fast, slow)
    assert fast[0] > 0


def test_compiled_scores_match_the_vectorised_ones():
    from easynav.localizers.navmap_voxel_scoring import COMPILED_SCORING

    if not COMPILED_SCORING.available():
        pytest.skip("numba not installed")
    # Particles over the whole room and beyond it (rays leaving the box), tilted ones, sensors
    # off the footprint's origin: occluded and visible points, in and out of the map. σ 0.15 m
    # on 0.1 m voxels puts probabilities on both sides of the ray check's 0.4 (0.41, 0.33).
    inflated = InflatedVoxelMap(VOXELS, 0.15, 0.01)
    assert {104, 84} <= set(np.unique(inflated.codes).tolist())
    rng = np.random.default_rng(3)
    points = ray_cast(VOXELS, (3.0, 2.0, 0.3), 0.0, rng)[::3] + (0.0, 0.0, 0.3)
    origins = np.tile((0.1, -0.05, 0.3), (len(points), 1))
    n = 200
    yaws = rng.uniform(-math.pi, math.pi, n)
    normals = rng.normal((0.0, 0.0, 1.0), 0.2, (n, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    rot = attitudes(yaws, normals)
    trans = np.column_stack((rng.uniform(-2.0, 12.0, n), rng.uniform(-2.0, 8.0, n),
                             rng.uniform(-0.5, 2.0, n)))
    compiled = score_particles(inflated, rot, trans, points, origins)
    vectorised = score_particles(inflated, rot, trans, points, origins, compiled=False)
    np.testing.assert_allclose(compiled, vectorised, rtol=1e-12, atol=1e-9)
    assert (compiled > 0).sum() > n // 2
    # Occlusion decided some of them: without it the sums would be larger.
    unoccluded = InflatedVoxelMap(VOXELS, 0.15, 0.01)
    unoccluded.tail_skip = 10**6
    assert (score_particles(unoccluded, rot, trans, points, origins) > compiled).any()
    # An empty map scores nothing; a particle or a point that is not finite scores 0.
    empty = InflatedVoxelMap(BonxaiMap(RES), 0.1, 0.01)
    for fast in (True, False):
        assert score_particles(empty, rot, trans, points, origins,
                               compiled=fast).tolist() == [0.0] * n
    trans[:3] = ((np.nan, 2.0, 0.0), (3.0, np.inf, 0.0), (3.0, 2.0, -np.inf))
    assert score_particles(inflated, rot, trans, points, origins)[:3].tolist() == [0.0] * 3
    points[:] = np.nan
    assert score_particles(inflated, rot, trans, points, origins).tolist() == [0.0] * n
    # The guard looks at the coordinates before flooring them: numba's floor of a NaN is an
    # arbitrary int64 (INT64_MIN on x86-64), which a box starting there would take for its first
    # voxel, occupied here.
    from easynav.localizers._voxel_scoring_numba import score_kernel

    lowest = np.iinfo(np.int64).min
    sums = score_kernel(rot[:2], np.full((2, 3), np.nan), np.zeros((4, 3)), np.full((4, 3), np.nan),
                        np.full((1, 1, 1), 255, np.uint8), np.full(3, lowest), 0.1, 0, 255, 0.4)
    assert sums.tolist() == [0.0, 0.0]


def test_compiled_scoring_checks_shapes_and_broadcasts_one_origin():
    from easynav.localizers.navmap_voxel_scoring import COMPILED_SCORING

    if not COMPILED_SCORING.available():
        pytest.skip("numba not installed")
    inflated = InflatedVoxelMap(VOXELS, 0.1, 0.01)
    rot = attitudes(np.zeros(2), np.tile((0.0, 0.0, 1.0), (2, 1)))
    trans = np.array([[3.0, 2.0, 0.0], [3.1, 2.0, 0.0]])
    points = ray_cast(VOXELS, (3.0, 2.0, 0.3), 0.0, np.random.default_rng(4))[::5]
    one = score_particles(inflated, rot, trans, points, np.array([[0.0, 0.0, 0.3]]))
    every = score_particles(inflated, rot, trans, points, np.tile((0.0, 0.0, 0.3),
                                                                  (len(points), 1)))
    assert one.tolist() == every.tolist()
    with pytest.raises(ValueError, match=r"points must be \(M, 3\)"):
        score_particles(inflated, rot, trans, points[:, :2], points[:, :2])
    with pytest.raises(ValueError, match="translations"):
        score_particles(inflated, rot, trans[:1], points, points)


# -- the surface -------------------------------------------------------------------------------
def test_particles_keep_to_the_surface_up_the_ramp():
    sim = Sim({"num_particles": 200, "initial_pose.x": 0.5, "initial_pose.y": 5.0,
               "initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.02,
               "initial_pose.z": 0.0, "noise_translation": 0.02})
    amcl = sim.amcl
    sim.move(0.0)
    for _ in range(30):  # 3 m along the surface: 0.5 m on the floor, 2.5 m up the ramp
        sim.move(0.1)
        with amcl._lock:
            poses, z, on = amcl.filter.poses.copy(), amcl._z.copy(), amcl._on_mesh.copy()
        cids, heights = NAVMAP.locate(np.column_stack((poses[:, :2], z)), 0.5)
        assert on.all() and (cids >= 0).all()
        np.testing.assert_allclose(z, heights, atol=1e-9)  # z is the mesh's under them
    x_true = 1.0 + 2.5 * math.cos(SLOPE)
    pose = sim.pose()
    assert pose.x == pytest.approx(x_true, abs=0.1)
    assert pose.z == pytest.approx(float(ramp_z(x_true)), abs=0.05)
    assert np.mean(z) == pytest.approx(float(ramp_z(x_true)), abs=0.05)
    # Attitude from the NavCel normal: nose up by the ramp's slope (negative pitch in ROS).
    rot = rotation_of(pose)
    assert math.asin(-rot[2, 0]) == pytest.approx(-SLOPE, abs=0.01)
    assert math.atan2(rot[1, 0], rot[0, 0]) == pytest.approx(0.0, abs=0.05)


def test_imu_attitude_replaces_the_normal_but_not_the_yaw():
    sim = Sim({"initial_pose.x": 3.0, "initial_pose.y": 1.0, "initial_pose.yaw": 0.5,
               "initial_pose.z": 0.0, "initial_pose.std_dev_xy": 0.01,
               "initial_pose.std_dev_yaw": 0.01})
    roll, pitch = 0.1, -0.2
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    q = np.array((sr * cp, cr * sp, -sr * sp, cr * cp))  # roll then pitch, IMU yaw 0
    sim.nav_state.set("imu", ImuPerception(orientation=q, frame_id="base_footprint"))
    sim.move(0.0)
    sim.move(0.01)
    rot = rotation_of(sim.pose())
    assert math.asin(-rot[2, 0]) == pytest.approx(pitch, abs=1e-3)
    assert math.atan2(rot[2, 1], rot[2, 2]) == pytest.approx(roll, abs=1e-3)
    assert math.atan2(rot[1, 0], rot[0, 0]) == pytest.approx(0.5, abs=0.05)


def test_particles_leaving_the_mesh_are_floored_and_redrawn():
    sim = Sim({"num_particles": 100, "initial_pose.x": 9.0, "initial_pose.y": 4.0,
               "initial_pose.z": 1.5, "initial_pose.std_dev_xy": 0.05,
               "reseed_freq": 1000.0})
    amcl = sim.amcl
    sim.move(0.0)
    with amcl._lock:  # five particles beyond the east wall: no surface under them
        amcl.filter.poses[:5, 0] = 10.5
    sim.move(0.0)
    assert not amcl._on_mesh[:5].any() and amcl._on_mesh[5:].all()
    sim.t += 1.0
    sim.scan((9.0, 4.0, 1.5, 0.0))
    with amcl._lock:
        assert amcl._on_mesh.all()  # the reseed redrew them among the kept ones
        assert (amcl.filter.poses[:, 0] < 10.0).all()


@pytest.mark.parametrize("truth", [(7.0, 4.0, 1.5, 0.3), (7.0, 4.0, 0.0, 0.3)],
                         ids=["upper", "ground"])
def test_cloud_over_both_levels_converges_to_the_right_one(truth):
    x, y, z, yaw = truth
    sim = Sim({"num_particles": 300, "initial_pose.x": x + 0.2, "initial_pose.y": y - 0.2,
               "initial_pose.yaw": yaw + 0.1, "initial_pose.std_dev_xy": 0.4,
               "initial_pose.std_dev_yaw": 0.2, "reseed_freq": 5.0,
               "inflation_stddev": 0.15, "correct_max_points": 400}, seed=3)
    amcl = sim.amcl
    sim.move(0.0)
    with amcl._lock:
        levels = np.round(amcl._z, 1)
    assert (levels == 0.0).sum() > 60 and (levels == 1.5).sum() > 60  # spread over both
    for _ in range(25):
        sim.move(0.0, dt=0.2)
        sim.scan(truth)
    pose = sim.pose()
    assert pose.z == pytest.approx(z, abs=0.01)
    assert math.hypot(pose.x - x, pose.y - y) < 0.15
    assert abs(math.remainder(pose.yaw - yaw, 2 * math.pi)) < 0.1
    with amcl._lock:
        top = np.argsort(-amcl.filter.weights)[: len(amcl.filter) // 2]
        assert np.mean(np.abs(amcl._z[top] - z) < 0.01) > 0.9
    assert sim.nav_state.has("map.bonxai.inflated")


def test_correct_max_points_caps_the_work(monkeypatch):
    seen = []
    real = module.score_particles

    def spy(inflated, rot, trans, points, origins, *args):
        seen.append(len(points))
        return real(inflated, rot, trans, points, origins, *args)

    monkeypatch.setattr(module, "score_particles", spy)
    sim = Sim({"num_particles": 20, "initial_pose.x": 3.0, "initial_pose.y": 2.0,
               "initial_pose.z": 0.0, "correct_max_points": 50})
    sim.move(0.0)
    sim.scan((3.0, 2.0, 0.0, 0.0))
    assert sim.nav_state.get("lidar").points.shape[0] > 200
    assert seen == [50] and sim.amcl.last_points_used == 50
    sim2 = Sim({"num_particles": 20, "initial_pose.x": 3.0, "initial_pose.y": 2.0})
    sim2.move(0.0)
    sim2.scan((3.0, 2.0, 0.0, 0.0))
    assert seen[-1] == sim2.amcl.last_points_used <= 1500


@pytest.mark.parametrize("name, value", [
    ("weights_tau", 0.0), ("top_keep_fraction", 1.5), ("top_keep_fraction", 0.0),
    ("correct_max_points", 0), ("inflation_prob_min", 1.0), ("downsampled_cloud_size", 0.0),
    ("noise_translation", 0.0), ("min_noise_xy", -1.0), ("num_particles", 0),
])
def test_bad_parameters_fail_configure_naming_them(name, value):
    with pytest.raises(PluginConfigurationError, match=name.replace(".", r"\.")):
        Sim({name: value})


def test_invalid_inflation_stddev_falls_back_as_the_original():
    for value in (0.0, -1.0, math.nan):
        sim = Sim({"inflation_stddev": value})
        assert sim.amcl.inflation_stddev == 1.5
        assert "inflation_stddev" in sim.log.text()


def test_parameters_are_the_original_ones():
    names = [p.name for p in NavMapAMCLLocalizer.parameter_declarations()]
    for name in ("num_particles", "initial_pose.x", "initial_pose.y", "initial_pose.yaw",
                 "initial_pose.std_dev_xy", "initial_pose.std_dev_yaw", "reseed_freq",
                 "noise_translation", "noise_rotation", "noise_translation_to_rotation",
                 "min_noise_xy", "min_noise_yaw", "compute_odom_from_tf", "inflation_stddev",
                 "inflation_prob_min", "correct_max_points", "weights_tau", "top_keep_fraction",
                 "downsampled_cloud_size"):
        assert name in names
    assert "hit_sigma" not in names
    defaults = {p.name: p.default for p in NavMapAMCLLocalizer.parameter_declarations()}
    assert (defaults["inflation_stddev"], defaults["inflation_prob_min"],
            defaults["correct_max_points"], defaults["weights_tau"],
            defaults["top_keep_fraction"], defaults["downsampled_cloud_size"]) == (
        0.05, 0.01, 1500, 0.7, 0.2, 0.05)


@pytest.mark.parametrize("missing", ["map.navmap", "map.bonxai"])
def test_missing_maps_give_a_diagnostic_not_an_exception(missing):
    sim = Sim({"initial_pose.x": 3.0, "initial_pose.y": 2.0})
    sim.nav_state.erase(missing)
    sim.move(0.0)
    sim.move(0.1)
    sim.scan((3.1, 2.0, 0.0, 0.0))
    assert f"'{missing}'" in sim.log.text()
    assert not sim.nav_state.has("map.bonxai.inflated")
    if missing == "map.bonxai":
        assert sim.nav_state.has("robot_pose")  # the prediction goes on


def test_wrong_type_under_map_bonxai_is_diagnosed():
    sim = Sim({"initial_pose.x": 3.0, "initial_pose.y": 2.0}, maps=False)
    sim.nav_state.set("map.navmap", NAVMAP)
    sim.nav_state.set("map.bonxai", "not a map")
    sim.move(0.0)
    sim.scan((3.0, 2.0, 0.0, 0.0))
    assert "not a BonxaiMap" in sim.log.text()


def test_initialpose_sets_the_level_from_its_z():
    sim = Sim({"num_particles": 50})
    sim.move(0.0)
    pose = Odometry(Header(sim.t, "map"), "base_footprint",
                    Pose.from_xy_yaw(7.0, 4.0, 0.0, z=1.4))
    pose.pose_covariance = np.diag([0.01, 0.01, 0.0, 0.0, 0.0, 0.01]).ravel()
    sim.amcl.on_initial_pose(pose)
    sim.move(0.0)
    with sim.amcl._lock:
        assert np.allclose(sim.amcl._z, 1.5)
    assert sim.pose().z == pytest.approx(1.5)


def test_map_to_odom_carries_z_and_yaw():
    sim = Sim({"initial_pose.x": 7.0, "initial_pose.y": 4.0, "initial_pose.z": 1.5,
               "initial_pose.std_dev_xy": 0.01, "initial_pose.std_dev_yaw": 0.01})
    sim.move(0.0)
    sim.move(0.2)
    stamp, values = sim.buffer.lookup_transform_values("map", "odom", None)
    assert stamp == sim.t
    assert values[2] == pytest.approx(1.5)
    pose = sim.pose()
    # map → odom → footprint = the estimate (odometry planar at z 0).
    yaw = math.atan2(2 * values[6] * values[5], 1 - 2 * values[5] ** 2)
    ox, oy = sim.odom[0], sim.odom[1]
    assert values[0] + math.cos(yaw) * ox - math.sin(yaw) * oy == pytest.approx(pose.x)
    assert values[1] + math.sin(yaw) * ox + math.cos(yaw) * oy == pytest.approx(pose.y)


@pytest.mark.ros
def test_over_ros_odom_initialpose_tf_and_particles_with_height(ros):
    from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
    from nav_msgs.msg import Odometry as OdometryMsg
    from tf2_msgs.msg import TFMessage

    from easynav.system.localizer_node import subscribe_initial_pose

    namespace = f"navmap_amcl_ros_{next(_namespaces)}"
    get_tf_buffer(namespace).set_transform(
        TransformStamped(Header(0.0, "base_footprint"), "lidar",
                         Transform(np.array([0.0, 0.0, SENSOR_HEIGHT]))), "test", is_static=True)
    amcl = NavMapAMCLLocalizer()
    amcl.initialize(PluginContext(parameters=DictParameters({"navmap.num_particles": 50}),
                                  node=ros.node, namespace=namespace, now=lambda: 20.0),
                    "navmap")
    # What localizer_node does for its localizer: initialpose reaches the plugin's base.
    subscribe_initial_pose(ros.node, lambda: [amcl])
    nav_state = NavState()
    nav_state.set("map.navmap", NAVMAP)
    nav_state.set("map.bonxai", VOXELS)
    tf_messages, particles = [], []
    ros.node.create_subscription(TFMessage, "tf", tf_messages.append, 100)
    ros.node.create_subscription(PoseArray, "/localizer_node/navmap/particles",
                                 particles.append, 10)
    odom_pub = ros.node.create_publisher(OdometryMsg, "odom", 10)
    init_pub = ros.node.create_publisher(PoseWithCovarianceStamped, "initialpose", 10)
    init = PoseWithCovarianceStamped()
    init.header.frame_id = "map"
    init.pose.pose.position.x, init.pose.pose.position.y = 7.0, 4.0
    init.pose.pose.position.z = 1.5
    init.pose.pose.orientation.w = 1.0
    init.pose.covariance[0] = init.pose.covariance[7] = init.pose.covariance[35] = 0.01
    assert ros.spin_until(lambda: init_pub.get_subscription_count() > 0)
    init_pub.publish(init)
    assert ros.spin_until(lambda: abs(amcl.filter.estimate()[0] - 7.0) < 0.2)
    odom = OdometryMsg()
    odom.header.frame_id = "odom"
    odom.header.stamp.sec = 19
    odom.pose.pose.orientation.w = 1.0
    assert ros.spin_until(lambda: odom_pub.get_subscription_count() > 0)
    odom_pub.publish(odom)
    assert ros.spin_until(lambda: amcl._odom is not None)
    amcl.update_rt(nav_state)
    assert ros.spin_until(lambda: tf_messages)
    sent = tf_messages[-1].transforms[0]
    assert (sent.header.frame_id, sent.child_frame_id) == ("map", "odom")
    assert sent.transform.translation.z == pytest.approx(1.5)
    points = ray_cast(VOXELS, (7.0, 4.0, 1.5 + SENSOR_HEIGHT), 0.0, np.random.default_rng(0))
    nav_state.set("lidar", PointPerception(points, "lidar", 19.0))
    assert ros.spin_until(lambda: amcl._ros["particles"].get_subscription_count() > 0)
    amcl.update(nav_state)
    assert ros.spin_until(lambda: particles)
    heights = [p.position.z for p in particles[-1].poses]
    assert len(heights) == 50 and np.allclose(heights, 1.5)
    amcl.cleanup()


def test_the_estimate_takes_the_height_of_its_own_place():
    # Most weight on the upper level at (9, 4), a few heavier single particles on the ground at
    # (2, 4): the estimate is the heaviest place's, and so is its height (the best particle
    # overall stood on the ground, 1.5 m below).
    sim = Sim({"num_particles": 100, "initial_pose.x": 9.0, "initial_pose.y": 4.0,
               "initial_pose.z": 1.5, "initial_pose.std_dev_xy": 0.05})
    amcl = sim.amcl
    sim.move(0.0)
    with amcl._lock:
        amcl.filter.poses[:10, :2] = (2.0, 4.0)
        amcl._z[:10] = 0.0
        amcl._z[10:] = 1.5
        amcl._on_mesh[:] = True
        amcl.filter.weights[:10] = 0.04
        amcl.filter.weights[10:] = 0.6 / 90
        estimate = amcl.filter.estimate()
        assert math.hypot(estimate[0] - 9.0, estimate[1] - 4.0) < 0.2
        assert amcl._best_z() == 0.0
        assert amcl._best_z(estimate) == 1.5
