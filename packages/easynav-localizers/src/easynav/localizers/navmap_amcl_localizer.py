"""NavMapAMCLLocalizer (easynav_navmap_localizer/AMCLLocalizer): AMCL on a NavMap surface,
corrected with 3D scans against a Bonxai voxel map, as the original EasyNav's: prediction on the
NavMap (``map.navmap``), correction on the Bonxai map (``map.bonxai``)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from easynav.common.sensors import ImuPerception, PointPerception, PointPerceptionsOps
from easynav.common.sensors.point_perceptions_ops import transform_points
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE, NavStateKey
from easynav.core.plugins import Param
from easynav.core.types import (
    Header,
    Odometry,
    Pose,
    Transform,
    TransformStamped,
    Twist,
    normalize_angle,
    yaw_to_quaternion,
)
from easynav.core.types.quaternion import quaternion_multiply
from easynav.localizers.amcl_localizer import COVARIANCE_TRACE_KEY, AMCLLocalizer
from easynav.localizers.costmap_amcl_localizer import CostmapAMCLLocalizer
from easynav.localizers.navmap_voxel_scoring import InflatedVoxelMap, score_particles
from easynav.maps.navmap import NavMap
from easynav.maps.navmap.keys import MAP_NAVMAP
from easynav.maps.voxel import BonxaiMap
from easynav.maps.voxel.keys import MAP_BONXAI

MAP_BONXAI_INFLATED = NavStateKey(
    "map.bonxai.inflated",
    "InflatedVoxelMap",
    "the inflated likelihood map of map.bonxai (NavMap AMCL), built on first use; erase it to "
    "have it rebuilt from the current map.bonxai.",
)
IMU_KEY = NavStateKey(
    "imu", "ImuPerception", "the IMU reading whose roll and pitch tilt the NavMap AMCL's particles."
)
#: A particle is on the mesh when a NavCel's surface lies within this height of its predicted z
#: (the original's ``height_eps``); otherwise it is off the mesh (see the class docstring).
SNAP_HEIGHT_EPS = 0.5
#: The estimate's height comes from the best particle within this distance (m) of it.
Z_PLACE_RADIUS = 1.0
#: Weight of a particle off the mesh, and floor of the others (the original's 1e-6).
WEIGHT_FLOOR = 1e-6
#: inflation_stddev when the value given is not > 0 (the original's fallback).
INFLATION_STDDEV_FALLBACK = 1.5
#: The 13 parameters shared with the costmap AMCL (the original declares the same ones with the
#: same defaults), imported from it (two descriptions adapted: no KLD here, and the reseed keeps
#: top_keep_fraction).
_DESCRIPTIONS = {
    "num_particles": "particle count",
    "reseed_freq": "keep the best top_keep_fraction, redraw the others around them, this often",
}
_SHARED = (
    "num_particles", "initial_pose.x", "initial_pose.y", "initial_pose.yaw",
    "initial_pose.std_dev_xy", "initial_pose.std_dev_yaw", "reseed_freq", "noise_translation",
    "noise_rotation", "noise_translation_to_rotation", "min_noise_xy", "min_noise_yaw",
    "compute_odom_from_tf",
)


def _rpy_from_quaternion(q) -> tuple[float, float, float]:
    x, y, z, w = (float(v) for v in q)
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def attitudes(yaws: np.ndarray, normals: np.ndarray,
              roll_pitch: tuple[float, float] | None = None) -> np.ndarray:
    """Rotation matrices ``(N, 3, 3)`` of the robot footprint frame: with ``roll_pitch`` (from
    an IMU) ``Rz(yaw)·Ry(pitch)·Rx(roll)``; else x along the heading projected onto the surface
    of unit normal ``normals`` ``(N, 3)``, z the normal (the original's
    ``frame_from_normal_and_yaw``); a vertical heading falls back to yaw only."""
    c, s = np.cos(yaws), np.sin(yaws)
    n = len(yaws)
    if roll_pitch is not None:
        roll, pitch = roll_pitch
        cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
        rot = np.empty((n, 3, 3))
        rot[:, 0] = np.stack((c * cp, c * sp * sr - s * cr, c * sp * cr + s * sr), axis=1)
        rot[:, 1] = np.stack((s * cp, s * sp * sr + c * cr, s * sp * cr - c * sr), axis=1)
        rot[:, 2] = (-sp, cp * sr, cp * cr)
        return rot
    heading = np.stack((c, s, np.zeros(n)), axis=1)
    x_tan = heading - normals * np.einsum("ij,ij->i", heading, normals)[:, None]
    norm = np.linalg.norm(x_tan, axis=1)
    flat = norm < 1e-9
    x_tan = np.where(flat[:, None], heading, x_tan / np.where(flat, 1.0, norm)[:, None])
    z_axis = np.where(flat[:, None], (0.0, 0.0, 1.0), normals)
    y_axis = np.cross(z_axis, x_tan)
    return np.stack((x_tan, y_axis, z_axis), axis=2)


def _matrix_to_quaternion(m: np.ndarray) -> tuple[float, float, float, float]:
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        return ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s,
                0.25 * s)
    i = int(np.argmax(np.diag(m)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(max(1.0 + m[i, i] - m[j, j] - m[k, k], 1e-12))
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j, i] + m[i, j]) / s
    q[k] = (m[k, i] + m[i, k]) / s
    q[3] = (m[k, j] - m[j, k]) / s
    return q[0], q[1], q[2], q[3]


def upward_normals(navmap: NavMap, cids: np.ndarray) -> np.ndarray:
    """Unit normals of NavCels ``cids``, flipped to point up (the mesh's winding may vary)."""
    normals = np.array(navmap.normals[cids])
    normals[normals[:, 2] < 0.0] *= -1.0
    return normals


class NavMapAMCLLocalizer(AMCLLocalizer):
    """Monte Carlo localisation on a NavMap surface (``map.navmap``) with 3D scans scored on a
    Bonxai voxel map (``map.bonxai``), as the original's ``easynav_navmap_localizer``.

    The odometry (``odom`` topic or TF with ``compute_odom_from_tf``), ``initialpose``, the
    particle topics and ``map → odom`` are the simple AMCL's shared code; the particle cloud is
    its :class:`ParticleFilter2D` (x, y, yaw) plus, per particle, the height ``z`` and the unit
    normal of the NavCel under it.

    - Prediction (``update_rt``): every particle moves by the odometry increment with the
      original's noise, along its surface (the increment is taken in the particle's tilted
      frame, as the original composes poses), then its ``z`` snaps to the NavMap: the NavCel
      under its (x, y) whose surface is nearest its predicted height, within 0.5 m (the
      original's ``height_eps``). Under a mezzanine a ground particle stays on the ground.
      A particle with no NavCel within reach **leaves the mesh**: it keeps its predicted
      height, weighs :data:`WEIGHT_FLOOR` at the next correction (the original's floor for a
      particle without evidence) and so is among the first redrawn at the next reseed (a
      robot cannot be there; redrawing it at once in the RT loop would reseed between
      corrections). Attitude: roll and pitch of NavState ``imu`` (an :class:`ImuPerception`
      with an orientation, rotated into the footprint frame when TF knows the IMU's frame)
      with each particle's yaw, else the frame of the NavCel normal and the yaw (the original
      set the whole IMU quaternion, its yaw included, on every particle).
    - Particles whose level is unknown (the initial cloud, unless ``initial_pose.z`` is set)
      are put on a NavCel drawn at random among all those under their (x, y): the cloud
      spreads over every level and the scans choose. ``initialpose`` and a previous
      localizer's pose give the level through their z (nearest surface).
    - Correction (``update``): each ungrouped point perception is downsampled in its own frame
      (``downsampled_cloud_size``), moved into the footprint frame (TF, latest), and remembers
      its sensor's origin; at most ``correct_max_points`` points, evenly spaced through the
      cloud, are used (the original read and ignored it). Each point scores the probability of
      the inflated map (``map.bonxai.inflated``, an :class:`InflatedVoxelMap` built on first
      use with ``inflation_stddev`` / ``inflation_prob_min``) at its end voxel, zeroed when it
      is at least 0.4 and the ray from the sensor crosses an occupied voxel of ``map.bonxai``
      before it (see :mod:`navmap_voxel_scoring`). Hits (score sums) and possible (point
      counts) accumulate until the next reseed; weight = ``(hits/possible)^weights_tau``
      (floored at 1e-6), normalised.
    - Every ``1/reseed_freq`` s (the original's reseed): particles sorted by weight, the best
      ``top_keep_fraction`` kept, the others copies of kept ones (index from a half-normal of
      σ = 0.05·N, clipped to the kept ones) jittered with the kept ones' xy covariance and
      circular yaw spread (floors ``min_noise_xy`` / ``min_noise_yaw``), on their source's
      level; the accumulated hits restart.
    - Estimate: the filter's (weighted mean of the upper half, circular yaw); its z and
      attitude from the surface under it on the best particle's level. ``robot_pose`` has z,
      the 3D attitude, the xy/yaw covariance of the filter and z variance of the particles;
      ``map → odom`` carries z and yaw (the footprint frame stays level, REP 120).

    Parameters: the costmap AMCL's 13 (same names and defaults in the original), the original's
    six (``inflation_stddev`` not > 0 or NaN → 1.5 with a warning, as the original; the others
    fail configure when out of range, where the original replaced them silently) and
    ``initial_pose.z`` (NaN: any level; beyond the original).

    NavState: reads ``map.navmap``, ``map.bonxai``, ``imu``, the ungrouped point perceptions;
    writes ``robot_pose``, ``localizer.amcl.covariance_trace`` and ``map.bonxai.inflated``
    (when absent or built from another map object). Missing maps are warned (throttled),
    never raised: without ``map.navmap`` the particles move in x, y, yaw only and are not
    corrected; without ``map.bonxai`` they are not corrected.

    Thread contract: as :class:`AMCLLocalizer` (one lock guards the cloud; scoring runs on a
    snapshot outside it). Exceptions: :class:`PluginConfigurationError` naming the parameter.
    """

    NEEDS_MAPS = ("navmap",)
    REQUIRES_MAPS = ("bonxai",)  # the correction scores on the Bonxai voxels
    PARAMETERS = (
        *(replace(p, description=_DESCRIPTIONS.get(p.name, p.description))
          for p in CostmapAMCLLocalizer.PARAMETERS if p.name in _SHARED),
        Param("initial_pose.z", math.nan, "height of the initial level (NaN: any level under "
              "(x, y); not in the original)", "m", allow_nan=True, dynamic=False),
        Param("inflation_stddev", 0.05, "σ of the inflated likelihood map (not > 0: 1.5, as the "
              "original)", "m", allow_nan=True),
        Param("inflation_prob_min", 0.01, "inflated probabilities below this are dropped",
              gt=0.0, lt=1.0),
        Param("correct_max_points", 1500, "at most this many scan points per correction "
              "(evenly spaced; the original ignored it)", ge=1),
        Param("weights_tau", 0.7, "weight = (hits / possible)^tau", gt=0.0),
        Param("top_keep_fraction", 0.2, "share of the best particles kept at a reseed", gt=0.0,
              le=1.0),
        Param("downsampled_cloud_size", 0.05, "voxel of the per-sensor downsampling", "m",
              gt=0.0),
    )
    TOPICS = CostmapAMCLLocalizer.TOPICS
    READS = (MAP_NAVMAP, MAP_BONXAI, MAP_BONXAI_INFLATED, IMU_KEY)
    WRITES = (ROBOT_POSE, COVARIANCE_TRACE_KEY, MAP_BONXAI_INFLATED)

    #: The TF odometry of the costmap AMCL (shared code, not a copy).
    _odometry_from_tf = CostmapAMCLLocalizer._odometry_from_tf

    @classmethod
    def parameter_declarations(cls):
        """The declarations without the simple AMCL's ``hit_sigma`` (not a model here)."""
        return tuple(p for p in super().parameter_declarations() if p.name != "hit_sigma")

    def __init__(self) -> None:
        super().__init__()
        self._z = np.zeros(1)
        self._normals = np.tile((0.0, 0.0, 1.0), (1, 1))
        self._on_mesh = np.ones(1, dtype=bool)
        self._hits = np.zeros(1)
        self._possible = np.zeros(1)
        self._acc_generation = -1
        self._rt_navmap: NavMap | None = None
        self._roll_pitch: tuple[float, float] | None = None
        self._level_hint = math.nan
        self._pending_levels = False
        self._last_z = 0.0
        self.inflation_stddev = 0.05
        self.last_points_used = 0

    # -- configuration ------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        p = self.params
        alias = self.plugin_name
        self.num_particles = int(p.num_particles)
        self._apply_tuning()
        with self._lock:
            self._generation += 1
            self.filter = type(self.filter)(self.num_particles)
            self.filter.seed(
                p["initial_pose.x"], p["initial_pose.y"], p["initial_pose.yaw"],
                np.eye(2) * p["initial_pose.std_dev_xy"] ** 2, p["initial_pose.std_dev_yaw"],
            )
            self._reset_levels(p["initial_pose.z"])
            self._odom = self._odom_used = self._odom_used_stamp = None
        self._last_reseed = self.now()
        self.logger.info(
            f"{alias}: {self.num_particles} particles around ({p['initial_pose.x']:g}, "
            f"{p['initial_pose.y']:g}, {p['initial_pose.yaw']:g}), inflation σ "
            f"{self.inflation_stddev:g} m, at most {p.correct_max_points} points per correction"
        )
        if self.context.node is not None:
            self._create_ros()

    def _apply_tuning(self) -> None:
        p = self.params
        self.reseed_period = 1.0 / p.reseed_freq
        self.noise = (p.noise_translation, p.noise_rotation, p.noise_translation_to_rotation)
        self.min_noise_xy, self.min_noise_yaw = p.min_noise_xy, p.min_noise_yaw
        sigma = p.inflation_stddev
        if not (math.isfinite(sigma) and sigma > 0.0):
            self.logger.warning(
                f"{self.plugin_name}.inflation_stddev = {sigma}: not > 0, using "
                f"{INFLATION_STDDEV_FALLBACK} (the original's fallback)"
            )
            sigma = INFLATION_STDDEV_FALLBACK
        self.inflation_stddev = sigma

    def on_parameter_changed(self, name: str, value: object) -> None:
        """Noise, reseed and scoring parameters apply from the next update (a new inflation
        σ or minimum rebuilds ``map.bonxai.inflated`` at the next correction)."""
        self._apply_tuning()

    def _reset_levels(self, z_hint: float) -> None:
        """Every particle's level from ``z_hint`` (NaN: any) at the next snap. Lock held."""
        n = len(self.filter)
        self._z = np.full(n, float(z_hint))
        self._normals = np.tile((0.0, 0.0, 1.0), (n, 1))
        self._on_mesh = np.ones(n, dtype=bool)
        self._pending_levels = True
        self._level_hint = float(z_hint)

    def reset_pose(self, x: float, y: float, yaw: float, cov_xy: np.ndarray, var_yaw: float,
                   z: float = math.nan) -> None:
        """Redraw the cloud around ``(x, y, yaw)`` (see :class:`AMCLLocalizer`) on the level
        nearest ``z`` (NaN: any level under each particle)."""
        super().reset_pose(x, y, yaw, cov_xy, var_yaw)
        with self._lock:
            self._reset_levels(z)
            navmap = self._rt_navmap
            if navmap is not None:
                self._snap(navmap, self._z)

    def on_last_known_pose(self, pose: Odometry) -> None:
        cov = np.asarray(pose.pose_covariance, dtype=float).reshape(6, 6)
        self.reset_pose(pose.pose.x, pose.pose.y, pose.pose.yaw, cov[:2, :2], cov[5, 5],
                        pose.pose.z)

    def on_initial_pose(self, pose: Odometry) -> None:
        """``initialpose``: the cloud from its covariance (floors ``min_noise_*``), on the
        level nearest its z."""
        self.on_last_known_pose(pose)

    # -- the surface --------------------------------------------------------------------------
    def _snap(self, navmap: NavMap, z_guess: np.ndarray) -> None:
        """Put every particle on the NavCel under it nearest ``z_guess`` (within
        :data:`SNAP_HEIGHT_EPS`); NaN guesses draw a level among all under (x, y). Lock held."""
        poses = self.filter.poses
        unknown = ~np.isfinite(z_guess)
        z = np.where(unknown, 0.0, z_guess)
        cids, heights = navmap.locate(np.column_stack((poses[:, :2], z)), SNAP_HEIGHT_EPS)
        if unknown.any():
            idx = np.flatnonzero(unknown)
            pidx, tidx = navmap.grid.candidates(poses[idx, :2])
            ok, zs = navmap.grid.evaluate(poses[idx, :2], pidx, tidx)
            pidx, tidx, zs = pidx[ok], tidx[ok], zs[ok]
            cids[idx] = -1
            if len(pidx):
                # One random candidate per particle: sort by (particle, random key).
                order = np.lexsort((self.filter.rng.random(len(pidx)), pidx))
                pidx, tidx, zs = pidx[order], tidx[order], zs[order]
                first = np.ones(len(pidx), dtype=bool)
                first[1:] = pidx[1:] != pidx[:-1]
                cids[idx[pidx[first]]] = tidx[first]
                heights[idx[pidx[first]]] = zs[first]
        found = cids >= 0
        self._on_mesh = found
        self._z = np.where(found, heights, z_guess)
        if found.any():
            self._normals[found] = upward_normals(navmap, cids[found])
        self._pending_levels = bool((~found & unknown).any())

    def _rotations(self, poses: np.ndarray, normals: np.ndarray) -> np.ndarray:
        return attitudes(poses[:, 2], normals, self._roll_pitch)

    # -- prediction (RT) ----------------------------------------------------------------------
    def update_rt(self, nav_state: NavState) -> None:
        """Read the NavMap and the IMU, then the shared prediction (:meth:`_predict`), which
        writes ``robot_pose`` and broadcasts ``map → odom``. RT thread."""
        if self.params.compute_odom_from_tf:
            self._odometry_from_tf()
        navmap = nav_state.get(MAP_NAVMAP) if nav_state.has(MAP_NAVMAP) else None
        if navmap is None:
            self._throttle.warn(
                self.logger, "no-navmap", f"{self.plugin_name}: no '{MAP_NAVMAP}' NavMap yet: "
                "particles move in x, y, yaw only (no height, no attitude)"
            )
        self._rt_navmap = navmap
        self._roll_pitch = self._imu_roll_pitch(nav_state)
        if navmap is not None and self._pending_levels:
            with self._lock:
                self._snap(navmap, self._z)
        super().update_rt(nav_state)

    def _imu_roll_pitch(self, nav_state: NavState) -> tuple[float, float] | None:
        if not nav_state.has(IMU_KEY):
            return None
        imu = nav_state.get(IMU_KEY)
        if not isinstance(imu, ImuPerception) or not imu.valid or not imu.has_orientation:
            return None
        q = np.asarray(imu.orientation, dtype=float)
        if not np.isfinite(q).all() or float(q @ q) < 1e-12:
            return None
        q = q / math.sqrt(float(q @ q))
        buffer = get_tf_buffer(self.context.namespace)
        footprint = buffer.get_tf_info().robot_footprint_frame
        if imu.frame_id and imu.frame_id != footprint:
            try:  # world←footprint = world←imu · imu←footprint
                _, values = buffer.lookup_transform_values(imu.frame_id, footprint, None)
                q = quaternion_multiply(q, np.asarray(values[3:7], dtype=float))
            except Exception:  # noqa: BLE001 - no mounting known: the IMU is taken as level
                pass
        roll, pitch, _ = _rpy_from_quaternion(q)
        return roll, pitch

    def _predict(self, dx: float, dy: float, dyaw: float) -> None:
        """The filter's noisy planar motion, re-applied along each particle's tilted frame,
        then the snap to the NavMap. RT thread, lock held."""
        old = self.filter.poses.copy()
        self.filter.predict(dx, dy, dyaw, *self.noise)
        navmap = self._rt_navmap
        if navmap is None:
            return
        delta = self.filter.poses[:, :2] - old[:, :2]
        c, s = np.cos(old[:, 2]), np.sin(old[:, 2])
        forward = c * delta[:, 0] + s * delta[:, 1]  # the noisy increment, robot frame
        side = -s * delta[:, 0] + c * delta[:, 1]
        rot = self._rotations(old, self._normals)
        move = forward[:, None] * rot[:, :, 0] + side[:, None] * rot[:, :, 1]
        self.filter.poses[:, :2] = old[:, :2] + move[:, :2]
        self._snap(navmap, self._z + move[:, 2])

    # -- correction (non-RT) ------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Score the particles on ``map.bonxai``; reseed when due; write ``robot_pose``."""
        alias = self.plugin_name
        if not nav_state.has(MAP_NAVMAP):
            self._throttle.warn(self.logger, "no-navmap",
                                f"{alias}: no '{MAP_NAVMAP}' NavMap yet: no correction")
            return
        if not nav_state.has(MAP_BONXAI):
            self._throttle.warn(self.logger, "no-bonxai",
                                f"{alias}: no '{MAP_BONXAI}' voxel map yet (a "
                                "BonxaiMapsManager writes it): no correction")
            return
        inflated = self._inflated(nav_state)
        if inflated is None:
            return
        scan = self._scan(nav_state)
        if scan is None:
            return
        points, origins = scan
        navmap = nav_state.get(MAP_NAVMAP)
        self._rt_navmap = navmap  # also for the reseed's snap before any RT cycle ran
        with self._lock:
            if self._pending_levels:
                self._snap(navmap, self._z)
            poses = self.filter.poses.copy()
            z = self._z.copy()
            normals = self._normals.copy()
            on_mesh = self._on_mesh.copy()
            generation = self._generation
        rot = self._rotations(poses, normals)
        trans = np.column_stack((poses[:, :2], np.nan_to_num(z)))
        sums = score_particles(inflated, rot, trans, points, origins)
        if self._acc_generation != generation or len(self._hits) != len(poses):
            self._hits = np.zeros(len(poses))
            self._possible = np.zeros(len(poses))
            self._acc_generation = generation
        self._hits += sums
        self._possible += len(points)
        ratio = np.clip(self._hits / np.maximum(self._possible, 1.0), WEIGHT_FLOOR, 1.0)
        weights = np.where(on_mesh, ratio ** self.params.weights_tau, WEIGHT_FLOOR)
        now = self.now()
        with self._lock:
            if generation == self._generation:  # not redrawn (initialpose) while scoring
                self.filter.set_weights(weights)
            if now - self._last_reseed >= self.reseed_period or now < self._last_reseed:
                self._reseed()
                self._last_reseed = now
            estimate = self.filter.estimate()
            covariance = self.filter.covariance(estimate)
            poses = self.filter.poses.copy()
            self._level_hint = self._best_z(estimate)
            z = self._z.copy()
        self._write_pose(nav_state, estimate, covariance, self._odom)
        self._publish_particles(poses, estimate, covariance, z)

    def _inflated(self, nav_state: NavState) -> InflatedVoxelMap | None:
        """``map.bonxai.inflated``, built (and stored) when absent or made from another map or
        with other parameters."""
        source = nav_state.get(MAP_BONXAI)
        if not isinstance(source, BonxaiMap):
            self._throttle.warn(self.logger, "bonxai-type", f"{self.plugin_name}: "
                                f"'{MAP_BONXAI}' is a {type(source).__name__}, not a BonxaiMap")
            return None
        current = nav_state.get(MAP_BONXAI_INFLATED) if nav_state.has(MAP_BONXAI_INFLATED) else None
        sigma, p_min = self.inflation_stddev, self.params.inflation_prob_min
        if (isinstance(current, InflatedVoxelMap) and current.source is source
                and current.sigma == sigma and current.p_min == p_min):
            return current
        try:
            inflated = InflatedVoxelMap(source, sigma, p_min)
        except ValueError as exc:
            self._throttle.warn(self.logger, "inflate", f"{self.plugin_name}: cannot inflate "
                                f"'{MAP_BONXAI}': {exc}")
            return None
        nav_state.set(MAP_BONXAI_INFLATED, inflated)
        self.logger.info(f"{self.plugin_name}: '{MAP_BONXAI_INFLATED}' built "
                         f"({inflated.codes.shape} voxels, σ {sigma:g} m)")
        return inflated

    def _scan(self, nav_state: NavState) -> tuple[np.ndarray, np.ndarray] | None:
        """Points (footprint frame) and their sensors' origins, downsampled per sensor and
        capped at ``correct_max_points``; None (warned) when there are none."""
        perceptions = nav_state.get_no_group(PointPerception)
        alias = self.plugin_name
        if not perceptions:
            self._throttle.warn(self.logger, "no-perceptions", f"{alias}: no point perceptions")
            return None
        buffer = get_tf_buffer(self.context.namespace)
        frame = buffer.get_tf_info().robot_footprint_frame
        size = self.params.downsampled_cloud_size
        points, origins = [], []
        for name, perception in perceptions.items():
            cloud = PointPerceptionsOps({name: perception}).downsample(size).as_points()
            if len(cloud) == 0:
                continue
            values = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
            if perception.frame_id and perception.frame_id != frame:
                try:
                    _, values = buffer.lookup_transform_values(frame, perception.frame_id, None)
                except Exception as exc:  # noqa: BLE001 - any lookup failure: skip the sensor
                    self._throttle.warn(self.logger, ("tf", name), f"{alias}: '{name}' skipped: "
                                        f"no transform {frame} -> {perception.frame_id} ({exc})")
                    continue
            cloud = transform_points(cloud, values)
            finite = np.isfinite(cloud).all(axis=1)
            points.append(cloud[finite])
            origins.append(np.tile(values[:3], (int(finite.sum()), 1)))
        if not points or sum(len(p) for p in points) == 0:
            self._throttle.warn(self.logger, "no-points", f"{alias}: no points to correct with")
            return None
        points, origins = np.concatenate(points), np.concatenate(origins)
        cap = int(self.params.correct_max_points)
        if len(points) > cap:
            keep = np.linspace(0, len(points) - 1, cap).round().astype(np.int64)
            points, origins = points[keep], origins[keep]
        self.last_points_used = len(points)
        return points, origins

    def _reseed(self) -> None:
        """The original's reseed (see the class docstring). Lock held."""
        f = self.filter
        n = len(f)
        top_count = max(1, min(n, int(math.floor(n * self.params.top_keep_fraction))))
        order = np.argsort(-f.weights, kind="stable")
        f.poses, f.weights = f.poses[order], f.weights[order]
        self._z, self._normals = self._z[order], self._normals[order]
        self._on_mesh = self._on_mesh[order]
        if top_count < n:
            top_w = f.weights[:top_count] / max(f.weights[:top_count].sum(), 1e-300)
            mean = top_w @ f.poses[:top_count, :2]
            d = f.poses[:top_count, :2] - mean
            cov = (top_w[:, None] * d).T @ d
            values, vectors = np.linalg.eigh(0.5 * (cov + cov.T))
            std = np.sqrt(np.maximum(values, self.min_noise_xy**2))
            yaw_r = math.hypot(top_w @ np.cos(f.poses[:top_count, 2]),
                               top_w @ np.sin(f.poses[:top_count, 2]))
            std_yaw = max(math.sqrt(max(0.0, -2.0 * math.log(max(yaw_r, 1e-12)))),
                          self.min_noise_yaw)
            m = n - top_count
            picks = np.minimum(np.abs(np.round(
                f.rng.normal(0.0, max(1.0, 0.05 * n), m))).astype(np.int64), top_count - 1)
            noise = f.rng.standard_normal((m, 3))
            offsets = (noise[:, :2] * std) @ vectors.T
            f.poses[top_count:, :2] = f.poses[picks, :2] + offsets
            f.poses[top_count:, 2] = normalize_angle(f.poses[picks, 2] + std_yaw * noise[:, 2])
            f.weights[top_count:] = f.weights[picks]
            self._z[top_count:] = self._z[picks]
            self._normals[top_count:] = self._normals[picks]
            if self._rt_navmap is not None:
                self._snap(self._rt_navmap, self._z)
        total = f.weights.sum()
        f.weights = f.weights / total if total > 0 else np.full(n, 1.0 / n)
        f.unweighed = None
        self._generation += 1  # hits and possible restart with the new cloud

    def _best_z(self, estimate: tuple[float, float, float] | None = None) -> float:
        """Height of the best particle on the mesh (NaN when none is), among those within
        :data:`Z_PLACE_RADIUS` of ``estimate`` when any is: the estimate is the heaviest place's
        (``ParticleFilter2D.estimate``), and the best particle overall may stand elsewhere, on
        another floor. Lock held."""
        usable = self._on_mesh & np.isfinite(self._z)
        if estimate is not None:
            near = usable & (np.hypot(self.filter.poses[:, 0] - estimate[0],
                                      self.filter.poses[:, 1] - estimate[1]) <= Z_PLACE_RADIUS)
            if near.any():
                usable = near
        weights = np.where(usable, self.filter.weights, -1.0)
        best = int(np.argmax(weights))
        return float(self._z[best]) if weights[best] >= 0.0 else math.nan

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        super()._create_ros()
        if self.params.compute_odom_from_tf:  # odometry from TF: no odom subscription
            self._odom_node.destroy_subscription(self._ros.pop("odom"))

    # -- outputs ------------------------------------------------------------------------------
    def _estimate_3d(self, estimate) -> tuple[float, np.ndarray, float]:
        """``(z, rotation 3×3, var z)`` of a planar estimate: the surface under it on the best
        particle's level (the hint's height when the mesh is not under it)."""
        x, y, yaw = estimate
        with self._lock:
            hint = self._best_z(estimate)
            if not math.isfinite(hint):
                hint = self._level_hint
            z_all, w = self._z.copy(), self.filter.weights.copy()
        self._level_hint = hint
        navmap = self._rt_navmap
        z, normal = (hint if math.isfinite(hint) else 0.0), np.array([[0.0, 0.0, 1.0]])
        if navmap is not None and math.isfinite(hint):
            cids, heights = navmap.locate(np.array([[x, y, hint]]), SNAP_HEIGHT_EPS)
            if cids[0] >= 0:
                z, normal = float(heights[0]), upward_normals(navmap, cids)
        rot = attitudes(np.array([yaw]), normal, self._roll_pitch)[0]
        finite = np.isfinite(z_all)
        var_z = float(w[finite] @ np.square(z_all[finite] - z)) if finite.any() else 0.0
        return z, rot, var_z

    def _write_pose(self, nav_state: NavState, estimate, covariance, odom) -> None:
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        x, y, _ = estimate
        z, rot, var_z = self._estimate_3d(estimate)
        cov6 = np.zeros((6, 6))
        cov6[np.ix_((0, 1, 5), (0, 1, 5))] = covariance
        cov6[2, 2] = var_z
        self._last_z = z
        pose = Odometry(
            header=Header(odom.header.stamp if odom is not None else self.now(), tf_info.map_frame),
            child_frame_id=tf_info.robot_footprint_frame,
            pose=Pose(x, y, z, *_matrix_to_quaternion(rot)),
            pose_covariance=cov6,
            twist=odom.twist if odom is not None else Twist(),
        )
        nav_state.set(ROBOT_POSE, pose)
        nav_state.set(COVARIANCE_TRACE_KEY, float(np.trace(covariance)))

    def _send_map_to_odom(self, estimate, odom_xy_yaw, stamp: float) -> None:
        """``map → odom`` with the estimate's z and yaw (odometry z subtracted when it has
        one)."""
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        x, y, yaw = estimate
        ox, oy, oyaw = odom_xy_yaw
        odom = self._odom
        oz = odom.pose.z if odom is not None else 0.0
        t_yaw = normalize_angle(yaw - oyaw)
        c, s = math.cos(t_yaw), math.sin(t_yaw)
        z = self._last_z
        transform = TransformStamped(
            Header(stamp, tf_info.map_frame), tf_info.odom_frame,
            Transform(np.array((x - (c * ox - s * oy), y - (s * ox + c * oy), z - oz)),
                      np.array(yaw_to_quaternion(t_yaw))),
        )
        if self._broadcaster is not None:
            self._broadcaster.send_transform(transform)
        else:
            get_tf_buffer(self.context.namespace).set_transform(transform, self.plugin_name)

    def _publish_particles(self, poses, estimate, covariance, z=None) -> None:
        """``<alias>/particles`` with each particle's height (yaw-only orientation) and
        ``<alias>/pose`` with the estimate's z and attitude, each while subscribed."""
        particles = self._ros.get("particles")
        if particles is None:
            return
        if particles.get_subscription_count() > 0:
            from geometry_msgs.msg import PoseArray

            from easynav.system.ros.converters import header_to_msg, pose_to_msg

            tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
            odom = self._odom
            heights = np.zeros(len(poses)) if z is None else np.nan_to_num(z)
            msg = PoseArray(header=header_to_msg(
                Header(odom.header.stamp if odom else self.now(), tf_info.map_frame)))
            msg.poses = [pose_to_msg(Pose.from_xy_yaw(p[0], p[1], p[2], float(h)))
                         for p, h in zip(poses.tolist(), heights.tolist(), strict=True)]
            particles.publish(msg)
        self._publish_estimate(estimate, covariance)

    def _publish_estimate(self, estimate, covariance) -> None:
        estimate_pub = self._ros.get("pose")
        if estimate_pub is None or estimate_pub.get_subscription_count() == 0:
            return
        from geometry_msgs.msg import PoseWithCovarianceStamped

        from easynav.system.ros.converters import header_to_msg, pose_to_msg

        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        odom = self._odom
        msg = PoseWithCovarianceStamped(header=header_to_msg(
            Header(odom.header.stamp if odom else self.now(), tf_info.map_frame)))
        z, rot, var_z = self._estimate_3d(estimate)
        msg.pose.pose = pose_to_msg(Pose(estimate[0], estimate[1], z,
                                         *_matrix_to_quaternion(rot)))
        cov6 = np.zeros((6, 6))
        cov6[np.ix_((0, 1, 5), (0, 1, 5))] = covariance
        cov6[2, 2] = var_z
        msg.pose.covariance = cov6.ravel()
        estimate_pub.publish(msg)


__all__ = ["IMU_KEY", "MAP_BONXAI_INFLATED", "NavMapAMCLLocalizer", "attitudes"]
