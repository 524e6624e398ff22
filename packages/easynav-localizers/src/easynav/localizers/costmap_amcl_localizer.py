"""CostmapAMCLLocalizer (easynav_costmap_localizer/AMCLLocalizer): AMCL on a Costmap2D."""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE, NavStateKey
from easynav.core.plugins import Param, PluginConfigurationError, Topic
from easynav.core.types import Costmap2D, Header, Odometry, Pose
from easynav.localizers.amcl_localizer import (
    MIN_POINT_Z,
    AMCLLocalizer,
    moved_by_increment,
    odometry_increment,
)
from easynav.localizers.costmap_sampling import (
    RESET_FINE_SIGMA,
    RESET_STRIDE,
    beam_likelihood_field,
    kld_particle_count,
    refined_fit,
    sample_free_space,
    scan_match,
    spread_poses,
)
from easynav.localizers.particle_filter import ParticleFilter2D, hit_fractions, likelihood_field
from easynav.maps.costmap.keys import MAP_BASE

#: Set it to True to ask for a global localisation (the localizer sets it back to False).
GLOBAL_LOCALIZATION_REQUEST = NavStateKey(
    "localizer.reinitialize_global_localization",
    "bool",
    "True asks the costmap AMCL to spread its particles over the free space (it resets it).",
)
COVARIANCE_TRACE = NavStateKey(
    "localizer.amcl.covariance_trace", "float", "var x + var y + var yaw of the particles."
)
HIT_COUNT = "hit_count"
#: Sensor resetting searches only when at least this share of the cloud is redrawn (the
#: scores fell markedly): the search costs ~0.15 s of the non-RT thread on a 30 × 15 m map.
RESET_MIN_SHARE = 0.1
#: Each search compares its best place with the cloud's estimate (both refined). The robot
#: was carried when the best is elsewhere (LOOKALIKE_DISTANCE m or LOOKALIKE_TURN rad away)
#: and the estimate fits the scan less than (1 - SEARCH_LOST_DROP) of the best's fit, or the
#: score fell below CARRIED_DROP of the long-term average. A redraw from the scores' drop goes
#: ahead for a carried robot or when the best is the cloud's own place; a place elsewhere that
#: is better but not clearly so (a look-alike where the world differs from the map: two
#: pallets moved, 7 %; or a few noisy scans that lowered every place's fit) gets nothing, and
#: the averages restart. A kidnap episode (a redraw from the search) is checked at the first
#: reseed at least SEARCH_RETRY_PERIOD s after its last search, and redraws again (at most
#: SEARCH_RETRIES times) when the best is elsewhere and fits the scan better than the estimate
#: by more than LOOKALIKE_MARGIN of its fit, and the robot was carried or its scores are
#: still more than SEARCH_LOST_DROP below their level before the drop. Otherwise the episode
#: ends. Measured without ROS on the depot (96 poses, 360 beams, range noise 1-5 cm): the
#: true pose fits 0.99-1.01 of the best place's fit, the hall's mirror image 0.30-0.93 of it.
SEARCH_RETRY_PERIOD = 2.0
SEARCH_RETRIES = 5
SEARCH_LOST_DROP = 0.3
#: A carried robot's scores fall by half at once: the lowest score of the last CARRIED_WINDOW
#: s against the long-term average (the mean since the last restart while fewer than
#: 1/alpha_slow scores came; the cloud settles on the best local fit within a second, and the
#: score rises again before the search). Measured in the symmetric hall of the tests, carried
#: onto its cloud's mirror image, where one scan cannot tell the carry from a changed world:
#: 0.44-0.49; scans with 15 cm range noise 0.68-0.72, 25 cm 0.55-0.58, 30-35 cm (a failing
#: sensor) 0.41-0.52, which looks like a carry. Likelihood-field model; with hit_count the
#: carry onto a mirror image is not told apart (its scores fall to 0.55).
CARRIED_DROP = 0.5
CARRIED_WINDOW = 2.0
LOOKALIKE_MARGIN = 0.05
LOOKALIKE_DISTANCE = 1.0
LOOKALIKE_TURN = 0.5
#: A redraw after the check found the cloud on a wrong place: at least this share of the cloud
#: (its least likely particles), at the places that fit within LOOKALIKE_MARGIN of the best
#: only. The likelihood field scores a look-alike up to 90 % as well as the robot's place: 14 %
#: of the cloud redrawn at the robot's place (and its look-alikes) still held 17 % of the
#: weight a second later, and the estimate stayed on the look-alike through five redraws.
LOOKALIKE_SHARE = 0.5
LIKELIHOOD_FIELD = "likelihood_field"


@dataclass
class _KidnapEpisode:
    """Redraws from the search since the scores fell (see :data:`SEARCH_RETRY_PERIOD`)."""

    reference: float  # w_slow before the first redraw: how well the scan fitted before
    carried: bool  # the first search's verdict (see CARRIED_DROP)
    share: float  # the first redraw's share of the cloud
    last_search: float  # s (node clock)
    retries: int = 0
    retry_due: bool = False  # the check found a look-alike: redraw LOOKALIKE_SHARE there


def _seen_share(alpha: float, n: int) -> float:
    """``1 - (1 - alpha)^n``: the weight an exponential average started at 0 has given its
    first ``n`` values (exact for tiny ``alpha``, where the power rounds to 1)."""
    return -math.expm1(n * math.log1p(-alpha)) if alpha < 1.0 else 1.0


class CostmapAMCLLocalizer(AMCLLocalizer):
    """Monte Carlo localisation on NavState ``map.base`` (a :class:`Costmap2D`).

    The odometry, prediction (RT), ``robot_pose``, ``map → odom``, ``initialpose`` and the
    particle topics are the simple AMCL's (:class:`AMCLLocalizer`, shared code); this class adds
    the costmap, the parameters of the original EasyNav's easynav_costmap_localizer (13, with its
    defaults: noise_* 0.01, initial std_dev 0.5, min_noise_* 0.05) and:

    - ``sensor_model``: ``hit_count`` (the original: the fraction of the scan points that land on
      lethal (254) cells, here the lethal cells near free space, :func:`surface_cells`; hits and
      possible points accumulated across corrections until the next reseed, weight = hits /
      possible) or ``likelihood_field`` (Nav2's: each point scores
      ``pz = z_hit·exp(-d²/2σ²) + z_rand/laser_max_range`` with ``d`` the distance to the nearest
      lethal surface cell from an exact distance transform, the weight is multiplied by
      ``1 + Σ pz³``, the cloud is resampled when its effective size falls below half). Both
      score every particle at once (:func:`hit_fractions`, vectorised over particles × points).
    - KLD-adaptive particle count (``kld_sampling``): at each resample (each reseed in the
      hit-count model, which does not resample otherwise) the cloud is resized to Fox's bound
      for ``pf_err``/``pf_z`` within ``[min_particles, max_particles]``.
    - Global localisation: particles uniform over the free cells of ``map.base``
      (``max_particles`` of them with KLD, else ``num_particles``), on request: the service
      ``reinitialize_global_localization`` (std_srvs/Empty, as Nav2's), the parameter
      ``global_localization`` (true at configure or set true at runtime), or NavState
      ``localizer.reinitialize_global_localization`` = True.
    - Kidnapped-robot recovery (augmented MCL, Nav2's ``recovery_alpha_slow/fast``): when the
      short-term average score falls below the long-term one, that share of particles is
      redrawn at the next resample/reseed. Beyond the original and Nav2
      (``recovery_sensor_resetting``, on by default): redrawn where the current scan fits the
      map best (:func:`sensor_reset_poses`, a scan-to-map search over the free space, run
      with the scan of the update that redraws, outside the lock), instead of uniformly
      over the free space, which on a 30 × 15 m hall puts about one particle in 4000 near the
      robot.

    Every ``1/reseed_freq`` s the worse half is redrawn around the better half (the original's
    reseed, :meth:`ParticleFilter2D.reseed_worst_half`). With ``compute_odom_from_tf`` the
    odometry is ``odom → robot_footprint`` from TF instead of the ``odom`` topic.

    NavState: reads ``map.base``, the ungrouped point perceptions (points above z 0.1 m in the
    footprint frame), ``localizer.reinitialize_global_localization``; writes ``robot_pose``
    (map frame, covariance of the particles) and ``localizer.amcl.covariance_trace``.

    Thread contract: as :class:`AMCLLocalizer`; the service callback and runtime parameter
    changes only raise a flag that ``update`` (non-RT) acts on.
    Exceptions: configure fails naming a bad parameter; updates warn (throttled) and return.
    """

    PARAMETERS = (
        Param("num_particles", 100, "particle count (initial count with kld_sampling)", ge=1),
        Param("initial_pose.x", 0.0, "initial cloud mean x", "m"),
        Param("initial_pose.y", 0.0, "initial cloud mean y", "m"),
        Param("initial_pose.yaw", 0.0, "initial cloud mean yaw", "rad"),
        Param("initial_pose.std_dev_xy", 0.5, "initial spread in x and y", "m", gt=0.0),
        Param("initial_pose.std_dev_yaw", 0.5, "initial spread in yaw", "rad", gt=0.0),
        Param("reseed_freq", 1.0, "redraw the worse half this often", "Hz", gt=0.0),
        Param("noise_translation", 0.01, "predict σ per metre along each axis", gt=0.0),
        Param("noise_rotation", 0.01, "predict yaw σ per radian turned", gt=0.0),
        Param("noise_translation_to_rotation", 0.01, "predict yaw σ per metre", gt=0.0),
        Param("min_noise_xy", 0.05, "σ floor of reseeds and initial poses", "m", gt=0.0),
        Param("min_noise_yaw", 0.05, "σ floor of reseeds and initial poses", "rad", gt=0.0),
        Param("compute_odom_from_tf", False, "odometry from TF odom -> footprint, not 'odom'",
              dynamic=False),
        Param("sensor_model", HIT_COUNT, "hit_count (original) or likelihood_field (Nav2)",
              choices=(HIT_COUNT, LIKELIHOOD_FIELD)),
        Param("sigma_hit", 0.2, "likelihood_field: σ of a point's distance to an obstacle", "m",
              gt=0.0),
        Param("z_hit", 0.5, "likelihood_field: weight of the hit term", ge=0.0),
        Param("z_rand", 0.5, "likelihood_field: weight of the random term", ge=0.0),
        Param("laser_max_range", 10.0, "likelihood_field: range of the random term", "m", gt=0.0),
        Param("laser_likelihood_max_dist", 2.0, "likelihood_field: distances capped here", "m",
              gt=0.0),
        Param("kld_sampling", False, "adapt the particle count (KLD) at each resample"),
        Param("min_particles", 100, "KLD lower bound", ge=1),
        Param("max_particles", 5000, "KLD upper bound and global localisation count", ge=1),
        Param("pf_err", 0.01, "KLD: maximum error between true and estimated distribution",
              gt=0.0),
        Param("pf_z", 0.99, "KLD: upper standard normal quantile (used as Nav2 does)", gt=0.0),
        Param("recovery_alpha_slow", 0.0, "long-term score average rate (0: no recovery)",
              ge=0.0, le=1.0),
        Param("recovery_alpha_fast", 0.0, "short-term score average rate (0: no recovery)",
              ge=0.0, le=1.0),
        Param("recovery_sensor_resetting", True, "kidnapped-robot recovery redraws where the "
              "scan fits the map (a scan-to-map search), not uniformly over the free space"),
        Param("global_localization", False, "spread the particles over the free space (at "
              "configure, or when set true at runtime)"),
    )
    TOPICS = (
        Topic("odom", "nav_msgs/msg/Odometry", "sub"),
        Topic("initialpose", "geometry_msgs/msg/PoseWithCovarianceStamped", "sub"),
        Topic("particles", "geometry_msgs/msg/PoseArray", "pub"),
        Topic("pose", "geometry_msgs/msg/PoseWithCovarianceStamped", "pub"),
    )
    READS = (MAP_BASE, GLOBAL_LOCALIZATION_REQUEST)
    WRITES = (ROBOT_POSE, COVARIANCE_TRACE)
    NEEDS_MAPS = ("costmap",)

    def __init__(self) -> None:
        super().__init__()
        self._service = None
        self._global_requested = False
        self._lf_map: Costmap2D | None = None
        self._lf_field: np.ndarray | None = None
        self._lf_off = 0.0
        self._hits = np.zeros(0)
        self._possible = np.zeros(0)
        self._acc_generation = -1
        self._w_slow = 0.0
        self._w_fast = 0.0
        self._scores_seen = 0  # since the averages last restarted
        self._slow_sum = self._fast_sum = 0.0  # the averages before their start-up correction
        self._carried = False  # the last search's verdict, for the episode it starts
        self._recent_scores: deque[tuple[float, float]] = deque()  # (time, score), 2 s
        self._episode: _KidnapEpisode | None = None  # searches since the scores fell
        self._reset_map: Costmap2D | None = None
        self._reset_fields: tuple[np.ndarray, np.ndarray] | None = None
        self._reset_poses: np.ndarray | None = None  # ranked, best first; None: uniform redraws
        self._reset_odom: tuple[float, float, float] | None = None  # odometry of their scan
        self._redrawn = False  # _inject_random redrew in this update: no reseed after it

    # -- configuration ------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        p = self.params
        alias = self.plugin_name
        if p.kld_sampling and p.min_particles > p.max_particles:
            raise PluginConfigurationError(
                f"{alias}.min_particles = {p.min_particles} exceeds {alias}.max_particles = "
                f"{p.max_particles}"
            )
        self.num_particles = int(p.num_particles)
        self.noise = (p.noise_translation, p.noise_rotation, p.noise_translation_to_rotation)
        self.min_noise_xy, self.min_noise_yaw = p.min_noise_xy, p.min_noise_yaw
        self._field_map = self._field = None
        self._lf_map = self._lf_field = None
        self._restart_scores()
        self._episode = None
        self._reset_poses = None
        with self._lock:
            self._generation += 1
            self.filter = ParticleFilter2D(self.num_particles)
            self.filter.seed(
                p["initial_pose.x"],
                p["initial_pose.y"],
                p["initial_pose.yaw"],
                np.eye(2) * p["initial_pose.std_dev_xy"] ** 2,
                p["initial_pose.std_dev_yaw"],
            )
            self._odom = self._odom_used = self._odom_used_stamp = None
        self._global_requested = bool(p.global_localization)
        self._last_reseed = self.now()
        self.logger.info(
            f"{alias}: {self.num_particles} particles around ({p['initial_pose.x']:g}, "
            f"{p['initial_pose.y']:g}, {p['initial_pose.yaw']:g}), sensor model "
            f"{p.sensor_model}" + (", global localisation requested" if self._global_requested
                                   else "")
        )
        if self.context.node is not None:
            self._create_ros()

    @property
    def reseed_period(self) -> float:
        """Seconds between reseeds (``1 / reseed_freq``, read every cycle)."""
        return 1.0 / self.params.reseed_freq

    def on_parameter_changed(self, name: str, value) -> None:
        if name in ("noise_translation", "noise_rotation", "noise_translation_to_rotation"):
            p = self.params
            self.noise = (p.noise_translation, p.noise_rotation, p.noise_translation_to_rotation)
        elif name in ("min_noise_xy", "min_noise_yaw"):
            p = self.params
            self.min_noise_xy, self.min_noise_yaw = p.min_noise_xy, p.min_noise_yaw
        elif name == "global_localization" and value:
            self.request_global_localization()
        elif name in ("sigma_hit", "z_hit", "z_rand", "laser_max_range",
                      "laser_likelihood_max_dist"):
            self._lf_map = None  # rebuild the likelihood table

    def request_global_localization(self) -> None:
        """Spread the particles over the free space at the next correction. Any thread."""
        self._global_requested = True

    # -- prediction (RT) ----------------------------------------------------------------------
    def update_rt(self, nav_state: NavState) -> None:
        """Take the TF odometry when configured so, then the shared prediction. RT thread."""
        if self.params.compute_odom_from_tf:
            self._odometry_from_tf()
        super().update_rt(nav_state)

    def _odometry_from_tf(self) -> None:
        buffer = get_tf_buffer(self.context.namespace)
        info = buffer.get_tf_info()
        try:
            stamp, (tx, ty, _, qx, qy, qz, qw) = buffer.lookup_transform_values(
                info.odom_frame, info.robot_footprint_frame
            )
        except Exception as exc:  # noqa: BLE001 - any lookup failure: wait for the tree
            self._throttle.warn(
                self.logger, "tf-odom", f"{self.plugin_name}: no {info.odom_frame} -> "
                f"{info.robot_footprint_frame} transform yet ({exc})"
            )
            return
        yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        self._odom = Odometry(
            Header(stamp, info.odom_frame), info.robot_footprint_frame,
            Pose.from_xy_yaw(tx, ty, yaw),
        )

    # -- correction (non-RT) ------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Global localisation if asked; weigh the particles; resample/reseed; write the pose.
        Non-RT thread."""
        base = self._map_for_update(nav_state)
        if base is None:
            return
        if self._global_requested:
            self._global_requested = False
            self._spread_globally(base)
        points = self._scan_points(nav_state, base.resolution)
        if points is None:
            return
        with self._lock:
            snapshot = self.filter.poses.copy()
            generation = self._generation
            odom_at_scan = self._odom_used
        if self.params.sensor_model == LIKELIHOOD_FIELD:
            weights, score = self._likelihood_field_weights(snapshot, points, base)
        else:
            weights, score = self._hit_count_weights(snapshot, points, base, generation)
        now = self.now()
        self._track_scores(score)
        recent = self._recent_scores
        if recent and now < recent[-1][0]:
            recent.clear()  # the clock went back
        recent.append((now, score))
        while recent and (now - recent[0][0] > CARRIED_WINDOW or now < recent[0][0]):
            recent.popleft()
        reseed_due = now - self._last_reseed >= self.reseed_period or now < self._last_reseed
        self._prepare_sensor_reset(base, points, weights, reseed_due, now, score, odom_at_scan)
        self._redrawn = False
        with self._lock:
            if generation == self._generation:  # not redrawn (initialpose) while scoring
                self._apply(weights, base)
            if reseed_due:
                self._reseed(base)
                self._last_reseed = now
            estimate = self.filter.estimate()
            covariance = self.filter.covariance(estimate)
            poses = self.filter.poses.copy()
        self._write_pose(nav_state, estimate, covariance, self._odom)
        self._publish_particles(poses, estimate, covariance)

    def _map_for_update(self, nav_state: NavState) -> Costmap2D | None:
        """NavState ``map.base`` (None, warned, when missing or empty); takes a global
        localisation request from NavState (:attr:`_global_requested`). Non-RT thread."""
        alias = self.plugin_name
        if not nav_state.has(MAP_BASE):
            self._throttle.warn(self.logger, "no-map", f"{alias}: no '{MAP_BASE}' costmap yet")
            return None
        base = nav_state.get(MAP_BASE, Costmap2D)
        if base.width == 0 or base.height == 0:
            self._throttle.warn(self.logger, "empty-map", f"{alias}: '{MAP_BASE}' is empty")
            return None
        if nav_state.has(GLOBAL_LOCALIZATION_REQUEST) and nav_state.get(
            GLOBAL_LOCALIZATION_REQUEST
        ):
            nav_state.set(GLOBAL_LOCALIZATION_REQUEST, False)
            self._global_requested = True
        return base

    def _scan_points(self, nav_state: NavState, resolution: float) -> np.ndarray | None:
        perceptions = nav_state.get_no_group(PointPerception)
        if not perceptions:
            self._throttle.warn(self.logger, "no-perceptions",
                                f"{self.plugin_name}: no point perceptions")
            return None
        buffer = get_tf_buffer(self.context.namespace)
        frame = buffer.get_tf_info().robot_footprint_frame
        points = (
            PointPerceptionsOps(perceptions, buffer, self.logger)
            .fuse(frame)
            .filter((math.nan, math.nan, MIN_POINT_Z), (math.nan, math.nan, math.nan))
            .collapse((math.nan, math.nan, 0.0))
            .downsample(resolution)
            .as_points()
        )
        if len(points) == 0:
            self._throttle.warn(
                self.logger, "no-points",
                f"{self.plugin_name}: no points to correct with (none above z {MIN_POINT_Z} m "
                f"in {frame})",
            )
            return None
        return points[:, :2]

    def _hit_count_weights(self, poses, points, base, generation) -> tuple[np.ndarray, float]:
        """The original's model: hits on lethal cells / possible (in-map) points, accumulated
        since the last reseed."""
        if base is not self._field_map:  # map.base is replaced, never mutated: cache per object
            self._field, self._field_map = likelihood_field(base, 0.0), base
        fractions, possible = hit_fractions(poses, points, base, self._field)
        if self._acc_generation != generation or len(self._hits) != len(poses):
            self._hits = np.zeros(len(poses))
            self._possible = np.zeros(len(poses))
            self._acc_generation = generation
        self._hits += fractions * possible
        self._possible += possible
        weights = np.divide(self._hits, self._possible, out=np.zeros(len(poses)),
                            where=self._possible > 0)
        return weights, float(fractions.mean())

    def _likelihood_field_weights(self, poses, points, base) -> tuple[np.ndarray, float]:
        p = self.params
        if base is not self._lf_map:
            self._lf_field, self._lf_off = beam_likelihood_field(
                base, p.sigma_hit, p.z_hit, p.z_rand, p.laser_max_range,
                p.laser_likelihood_max_dist,
            )
            self._lf_map = base
        mean, inside = hit_fractions(poses, points, base, self._lf_field)
        total = mean * inside + (len(points) - inside) * self._lf_off
        return 1.0 + total, float((total / len(points)).mean())

    def _track_scores(self, score: float) -> None:
        """The long- and short-term score averages (Nav2's ``w_slow``, ``w_fast``), corrected
        for their start (each average divided by ``1 - (1 - alpha)^n`` after ``n`` scores, as
        Adam corrects its moments): Nav2 starts both at the first score, and ``w_slow``
        (alpha 0.001: 1000 scores, 200 s at 5 Hz) then stays near it. The first score after a
        recovery's redraw is the lost cloud's, low; ``w_fast`` rose above it once the robot was
        found and stayed above for minutes, so a second kidnap, or a look-alike place the
        cloud had settled on, went unnoticed (the depot's kidnap scenario: 5 m off for 400 s).
        Corrected, ``w_slow`` is the mean of the scores since the start while fewer than
        ``1/alpha`` have come."""
        p = self.params
        if p.recovery_alpha_slow <= 0.0 or p.recovery_alpha_fast <= 0.0:
            return
        self._scores_seen += 1
        n = self._scores_seen
        self._slow_sum += p.recovery_alpha_slow * (score - self._slow_sum)
        self._fast_sum += p.recovery_alpha_fast * (score - self._fast_sum)
        self._w_slow = self._slow_sum / _seen_share(p.recovery_alpha_slow, n)
        self._w_fast = self._fast_sum / _seen_share(p.recovery_alpha_fast, n)

    def _restart_scores(self) -> None:
        """Both averages start again from the next score (Nav2's reset after a redraw), and so
        does the window of recent scores (a lost cloud's score from before a redraw made the
        next search's verdict "carried")."""
        self._w_slow = self._w_fast = 0.0
        self._slow_sum = self._fast_sum = 0.0
        self._scores_seen = 0
        self._recent_scores.clear()

    def _recovery_share(self) -> float:
        """Augmented MCL's share of the cloud to redraw: ``1 - w_fast/w_slow`` (0 when off),
        or at least :data:`LOOKALIKE_SHARE` when the episode's check found a look-alike."""
        share = 0.0 if self._w_slow <= 0.0 else max(0.0, 1.0 - self._w_fast / self._w_slow)
        episode = self._episode
        if episode is not None and episode.retry_due:
            share = max(share, episode.share, LOOKALIKE_SHARE)
        return share

    def _prepare_sensor_reset(self, base: Costmap2D, points: np.ndarray,
                              weights: np.ndarray, reseed_due: bool, now: float,
                              score: float, odom_at_scan: tuple[float, float, float] | None
                              ) -> None:
        """When this update will redraw particles (a reseed, or a likelihood-field resample)
        and the scores fell, or a kidnap episode's check is due (:meth:`_check_episode`), rank
        the poses where this scan fits the map, for :meth:`_inject_random`, and compare the
        best with the cloud's estimate. Outside the lock: the search takes tens of
        milliseconds and the compiled scoring releases the GIL, so the RT loop runs
        meanwhile. The ranking is where the robot was at ``odom_at_scan`` (the odometry the
        scored cloud had reached); the redraw carries it on by the odometry since. Computed
        for this update's scan only."""
        self._reset_poses = None
        self._reset_odom = odom_at_scan
        if not self.params.recovery_sensor_resetting:
            return
        episode = self._episode
        check_due = episode is not None and reseed_due and (
            now - episode.last_search >= SEARCH_RETRY_PERIOD or now < episode.last_search)
        if not check_due:
            if self._recovery_share() < RESET_MIN_SHARE:
                return  # the few particles of an ordinary dip are drawn uniformly: no search
            if not reseed_due and self.params.sensor_model == LIKELIHOOD_FIELD:
                with self._lock:
                    prior = self.filter.weights.copy()
                posterior = prior * weights if len(prior) == len(weights) else weights
                total = posterior.sum()
                if total <= 0.0 or 1.0 / np.square(posterior / total).sum() >= 0.5 * len(
                        weights):
                    return  # no resample this time
            elif not reseed_due:
                return
        if base is not self._reset_map:
            self._reset_fields = (likelihood_field(base, RESET_STRIDE),
                                  likelihood_field(base, RESET_FINE_SIGMA))
            self._reset_map = base
        with self._lock:
            estimate = np.array(self.filter.estimate())
            odom_now = self._odom_used
        if odom_at_scan is not None and odom_now is not None:
            # Where the cloud was when the scan was taken: the RT loop has carried it on by
            # the odometry since (a robot turning at 1 rad/s turned 0.3 rad in a loaded 0.3 s).
            estimate = moved_by_increment(estimate, odometry_increment(odom_now, odom_at_scan))[0]
        try:
            ranked, fits = scan_match(base, points, *self._reset_fields)
        except ValueError:
            return
        here, fit = refined_fit(base, estimate, points, self._reset_fields[1])
        best, best_fit = ranked[0], float(fits[0])
        turn = abs((best[2] - here[2] + math.pi) % (2.0 * math.pi) - math.pi)
        elsewhere = (math.hypot(best[0] - here[0], best[1] - here[1]) > LOOKALIKE_DISTANCE
                     or turn > LOOKALIKE_TURN)
        lowest = min(value for _, value in self._recent_scores) if self._recent_scores else score
        self._carried = elsewhere and (fit < (1.0 - SEARCH_LOST_DROP) * best_fit
                                       or lowest < CARRIED_DROP * self._w_slow)
        if check_due:
            lookalike = elsewhere and fit < (1.0 - LOOKALIKE_MARGIN) * best_fit
            self._check_episode(lookalike, best, best_fit, here, fit, now, score)
            if self._episode is not None and self._episode.retry_due:
                self._reset_poses = spread_poses(
                    ranked[fits >= (1.0 - LOOKALIKE_MARGIN) * best_fit], len(weights),
                    self.filter.rng, (self.min_noise_xy, self.min_noise_yaw))
                return
            if self._recovery_share() < RESET_MIN_SHARE:
                return
        if elsewhere and not self._carried:
            # The scores fell, but no place fits the scan clearly better than the cloud's: the
            # best is a look-alike, a little better where the world differs from the map (two
            # pallets moved: 7 %), or a few noisy scans dipped every place's fit. Redrawn there,
            # the cloud of a robot that had not moved followed the look-alike (9 m, 3 seeds of
            # 4). Nothing is redrawn; the averages restart, as after a redraw, so that the
            # search is not run again at every reseed while the dip lasts.
            self._restart_scores()
            self._throttle.warn(
                self.logger, "no-better-place",
                f"{self.plugin_name}: the scores fell, but the scan fits no place clearly "
                f"better than the estimate (best ({best[0]:.2f}, {best[1]:.2f}): {best_fit:.2f} "
                f"against {fit:.2f}): nothing redrawn")
            return
        self._reset_poses = spread_poses(ranked, len(weights), self.filter.rng,
                                         (self.min_noise_xy, self.min_noise_yaw))

    def _check_episode(self, lookalike: bool, best: np.ndarray, best_fit: float,
                       here: np.ndarray, fit: float, now: float, score: float) -> None:
        """A kidnap episode's check (:data:`SEARCH_RETRY_PERIOD`): is the cloud on a wrong
        place? Then a redraw is due (``retry_due``: at least :data:`LOOKALIKE_SHARE` of the
        cloud, at the places that fit this scan within :data:`LOOKALIKE_MARGIN` of the best);
        else the episode ends (the robot is found, or was never lost).

        ``lookalike``: the search's ``best`` (fit ``best_fit``) is elsewhere and fits the scan
        more than the margin better than the refined estimate ``here`` (``fit``). The scores
        alone did not tell: a look-alike fits the scan almost as well as the robot's place
        (the depot's mirror image, up to 93 %), and the filter, whose cloud held both places
        after the redraw, settled on the mirror in one playground run in about thirty. The
        search alone did not either: with pallets moved, a robot on its true place fitted 7 %
        worse than its mirror image, and after a few noisy scans dipped its scores, three
        redraws carried its cloud there. So it acts for a carried robot
        (:attr:`_KidnapEpisode.carried`) or one whose scores are still low."""
        episode = self._episode
        episode.last_search = now
        lost = score < (1.0 - SEARCH_LOST_DROP) * episode.reference
        if lookalike and (episode.carried or lost):
            if episode.retries < SEARCH_RETRIES:
                episode.retry_due = True
                self.logger.info(
                    f"{self.plugin_name}: the scan fits ({best[0]:.2f}, {best[1]:.2f}, "
                    f"{best[2]:.2f}) better than the estimate ({here[0]:.2f}, {here[1]:.2f}, "
                    f"{here[2]:.2f}): {best_fit:.2f} against {fit:.2f}; redrawing there")
                return
            self.logger.warning(
                f"{self.plugin_name}: the scan still fits ({best[0]:.2f}, {best[1]:.2f}) "
                f"better than the estimate after {SEARCH_RETRIES} redraws; the filter decides")
        self._episode = None

    def _apply(self, weights: np.ndarray, base: Costmap2D) -> None:
        """Weigh the cloud (lock held); in the likelihood-field model resample when the cloud
        degenerates."""
        if self.params.sensor_model == HIT_COUNT:
            if not self.filter.set_weights(weights):
                self._throttle.warn(self.logger, "no-hits",
                                    f"{self.plugin_name}: no particle's points hit the map")
            return
        if not self.filter.correct(weights):
            return
        if self.filter.effective_sample_size() < 0.5 * len(self.filter):
            self._resample(base)

    def _resample(self, base: Costmap2D) -> bool:
        """Resample (KLD-sized); True when particles were redrawn for recovery."""
        p = self.params
        count = None
        if p.kld_sampling:
            count = kld_particle_count(self.filter.poses, p.pf_err, p.pf_z, p.min_particles,
                                       p.max_particles)
        self.filter.resample(count)
        injected = self._inject_random(base)
        self._generation += 1
        return injected

    def _reseed(self, base: Costmap2D) -> None:
        # hit_count never resamples between reseeds: KLD resizes the cloud here. (The
        # likelihood-field model resizes at its resamples only: resizing at every reseed
        # shrank a global cloud onto wrong modes before the scans had told them apart.)
        if self.params.sensor_model == HIT_COUNT and self.params.kld_sampling:
            injected = self._resample(base)
        else:
            injected = self._inject_random(base)
        # Not right after a redraw, this one or the likelihood-field resample's of this update:
        # the new particles have not been weighed yet. After a resample every weight is equal,
        # and the reseed's "upper half" was the redrawn half, copied over the rest: the whole
        # cloud went to the search's places.
        if not injected and not self._redrawn:
            self.filter.reseed_worst_half(self.min_noise_xy, self.min_noise_yaw)
        self._generation += 1  # hit counters restart with the new cloud

    def _inject_random(self, base: Costmap2D) -> bool:
        """Augmented MCL: redraw ``1 - w_fast/w_slow`` of the cloud, the least likely
        particles: with ``recovery_sensor_resetting`` where the scan fits the map (the ranking
        of :meth:`_prepare_sensor_reset`, best first; only when it is at least
        :data:`RESET_MIN_SHARE`), else uniformly over the free space (Nav2's). True when
        particles were redrawn."""
        share = self._recovery_share()
        count = int(share * len(self.filter))
        if count == 0:
            return False
        ranked, self._reset_poses = self._reset_poses, None
        if ranked is None and self.params.recovery_sensor_resetting:
            # With sensor resetting, redraws come from the search only: an ordinary dip
            # (below RESET_MIN_SHARE) redraws nothing (the reseed keeps the cloud alive), and
            # a marked drop without a search for this scan waits for the next update. A
            # uniform redraw would spend the averages' reset and end the recovery.
            return False
        # The least likely, ties in random order: after a resample every weight is equal, and
        # resampling keeps each place's copies in a run of indices (the first ``count`` could
        # be one whole place).
        shuffled = self.filter.rng.permutation(len(self.filter))
        order = shuffled[np.argsort(self.filter.weights[shuffled], kind="stable")][:count]
        if ranked is not None:
            poses, where = np.resize(ranked, (count, 3)), "where the scan fits the map"
            if self._reset_odom is not None and self._odom_used is not None:
                # The places fit the scan where the robot was; it has driven on since.
                poses = moved_by_increment(
                    poses, odometry_increment(self._reset_odom, self._odom_used))
        else:
            try:
                poses = sample_free_space(base, count, self.filter.rng)
            except ValueError:
                return False
            where = "over the free space"
        self.filter.redraw(order, poses)
        self._redrawn = True
        if ranked is not None:
            if self._episode is None:
                self._episode = _KidnapEpisode(
                    reference=self._w_slow, share=share, last_search=self.now(),
                    carried=self._carried)
            else:
                self._episode.retries += 1
                self._episode.last_search = self.now()
                self._episode.retry_due = False
        # Nav2's reset: both averages restart together at the next score, and no redraw
        # follows until the scores fall again (the episode redraws again while the cloud is
        # on a look-alike).
        self._restart_scores()
        self.logger.info(f"{self.plugin_name}: {count} particles redrawn {where} "
                         f"(scores fell: kidnapped?)")
        return True

    def reset_pose(self, x: float, y: float, yaw: float, cov_xy: np.ndarray,
                   var_yaw: float) -> None:
        """The shared reset (``initialpose``, a handover); a kidnap episode ends and the score
        averages start again (Nav2's ``pf_init``): the pose given overrides the search's."""
        super().reset_pose(x, y, yaw, cov_xy, var_yaw)
        self._episode = None
        self._restart_scores()

    def _spread_globally(self, base: Costmap2D) -> None:
        p = self.params
        count = int(p.max_particles if p.kld_sampling else p.num_particles)
        try:
            poses = sample_free_space(base, count, self.filter.rng)
        except ValueError as exc:
            self.logger.warning(f"{self.plugin_name}: global localisation impossible: {exc}")
            return
        with self._lock:
            self._generation += 1
            self.filter.replace(poses)
        self._restart_scores()
        self._episode = None
        self._last_reseed = self.now()
        self.logger.info(f"{self.plugin_name}: global localisation: {count} particles over "
                         "the free space")

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        super()._create_ros()
        node = self.context.node
        if self.params.compute_odom_from_tf:
            node.destroy_subscription(self._ros.pop("odom"))
        try:
            from std_srvs.srv import Empty
        except ImportError:
            self.logger.warning(f"{self.plugin_name}: std_srvs is not installed: no "
                                "reinitialize_global_localization service")
            return
        # Relative, like Nav2's AMCL: /reinitialize_global_localization in the node's namespace.
        self._service = node.create_service(
            Empty, "reinitialize_global_localization", self._on_global_localization
        )

    def _destroy_ros(self) -> None:
        service, self._service = self._service, None
        if service is not None and self.context.node is not None:
            self.context.node.destroy_service(service)
        super()._destroy_ros()

    def _on_global_localization(self, request, response):
        self.request_global_localization()
        return response
