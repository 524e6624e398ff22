"""MHAMCLLocalizer (easynav_mhamcl_localizer/MHAMCLLocalizer): multi-hypothesis AMCL on a
Costmap2D."""

from __future__ import annotations

import math
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass

import cv2
import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import NavStateKey
from easynav.core.plugins import Param, PluginConfigurationError
from easynav.core.types import Costmap2D, normalize_angle
from easynav.localizers.amcl_localizer import moved_by_increment, odometry_increment
from easynav.localizers.costmap_amcl_localizer import (
    LIKELIHOOD_FIELD,
    CostmapAMCLLocalizer,
)
from easynav.localizers.costmap_sampling import (
    RESET_FINE_SIGMA,
    RESET_REFINED,
    RESET_STRIDE,
    kld_particle_count,
    sensor_reset_poses,
)
from easynav.localizers.particle_filter import (
    ParticleFilter2D,
    hit_fractions,
    likelihood_field,
    surface_cells,
)

HYPOTHESES_COUNT = NavStateKey(
    "localizer.mhamcl.hypotheses", "int", "how many pose hypotheses the MH-AMCL keeps."
)
#: A quality (or a candidate's) below this counts as this in the log-likelihood (log 0).
_MIN_QUALITY = 1e-3
#: Smoothing of a hypothesis' quality between corrections (share of the newest value).
_QUALITY_SMOOTHING = 0.3
#: Costs at or above this (inscribed, lethal, unknown) are not where a robot can be.
_NOT_FREE = 253

_NOT_ORIGINAL = " (not in the original)"
_ACCEPTED = "accepted for the original's files, not used here: {}"


def _replace(params: tuple[Param, ...], *new: Param) -> tuple[Param, ...]:
    names = {p.name: p for p in new}
    return tuple(names.pop(p.name, p) for p in params) + tuple(names.values())


@dataclass(eq=False)
class Hypothesis:
    """One pose hypothesis: its particle cloud, its accumulated log-likelihood (relative: the
    best is 0 after every correction) and its smoothed quality (the best particle's share of
    the scan within 3σ of an obstacle)."""

    ident: int
    filter: ParticleFilter2D
    log_likelihood: float = 0.0
    quality: float | None = None

    def estimate(self) -> tuple[float, float, float]:
        return self.filter.estimate()


class MHAMCLLocalizer(CostmapAMCLLocalizer):
    """Multi-hypothesis Monte Carlo localisation on NavState ``map.base`` (a Costmap2D).

    Several particle filters (*hypotheses*) about where the robot is, each with its own cloud,
    weights and history; the pose of the best one is published. A subclass of the costmap AMCL:
    the odometry, ``map → odom``, ``initialpose``, the topics, the
    ``reinitialize_global_localization`` service and NavState request, the sensor models and the
    costmap AMCL's parameters are its (a costmap AMCL params file loads with only the plugin
    name changed); the original MH-AMCL's parameters (``easynav_mhamcl_localizer`` README) load
    too.

    - Prediction (RT): every hypothesis moves with the odometry.
    - Correction (non-RT): every hypothesis' particles are weighed against the scan (the costmap
      AMCL's ``likelihood_field`` model, or with ``hit_count`` the share of the points within
      ``distance_perception_error`` of an obstacle, soft ``exp(-d²/2σ²)``), all hypotheses in one
      vectorised scoring call; a cloud is resampled when its effective size falls below half.
      The *quality* of a hypothesis is the original's: the best particle's share of the scan
      within 3σ of an obstacle (at least one map cell: on a coarse map the grid, not the
      sensor, sets the error), smoothed. Its *accumulated log-likelihood* grows by
      ``log(quality)`` each correction (times ``hypo_likelihood_decay`` before, 1: no
      forgetting): two twins of a symmetric map stay equal until the scan tells them apart,
      then the wrong one falls behind, correction after correction.
    - Reseed (``reseed_freq``, the original's): the ``reseed_percentage_losers`` least likely
      particles are redrawn around the ``reseed_percentage_winners`` best with
      ``reseed_noise_xy/yaw``; the cloud grows by ``particles_step`` when the quality is below
      ``low_q_hypo_threshold`` and shrinks when above ``good_hypo_threshold`` (within
      ``[min_particles, max_particles]``; with ``kld_sampling`` KLD sizes it at resamples).
    - Creation (every ``1/hypotheses_freq`` s, and at a global localisation): the poses where
      the scan fits the whole map are searched (the costmap AMCL's sensor-resetting search,
      :func:`sensor_reset_poses`, in place of the original's cascade matcher), scored by
      quality, and clustered (poses within ``min_candidate_distance`` and ``min_candidate_angle``
      of a better one join its cluster); a cluster scoring at least ``min_candidate_weight``
      far from every hypothesis starts a new one (``new_hypothesis_std_xy/yaw``) with the
      best's log-likelihood plus ``log(new_hypothesis_ratio · q_candidate / q_best)``: a
      newcomer must explain the scans better for a while before it wins. A global localisation
      discards the hypotheses and starts one per cluster (at most ``max_hypotheses``, all even).
      The search runs in a thread of its own, as the original's map matching does: on a
      large map it takes seconds (the playground's campus: ~3 s), and run inside ``update``
      it left the hypotheses without a correction for as long (1.6 corrections per second
      instead of 5). ``update`` starts a search when one is due and
      none is running, and takes its candidates at the first update after it ends, moved by
      the odometry received since its scan.
    - Merge: two hypotheses within ``hypo_merge_distance`` and ``hypo_merge_angle`` become the
      more likely one. Prune: a hypothesis whose likelihood ratio to the best falls below
      ``hypo_prune_ratio``, whose quality falls below ``very_low_q_hypo_threshold``, or whose
      estimate leaves the free space, is removed (never the last). At most ``max_hypotheses``:
      a candidate replaces the least likely only if its quality is below
      ``low_q_hypo_threshold``.
    - Output: the selected hypothesis (covariance of its particles). Another one takes over when
      its quality is at least ``good_hypo_threshold`` and its accumulated likelihood exceeds the
      selected one's by ``1/(1 - min_hypo_diff_winner)`` (or the selected one is removed); the
      switch is logged.

    ``multihypothesis`` false: one hypothesis, no creation (a plain AMCL with the original's
    reseed). NavState: as the costmap AMCL; also writes ``localizer.mhamcl.hypotheses``.
    Thread contract: as :class:`CostmapAMCLLocalizer`; the search runs in a thread of its own
    (attribute ``search_in_background``, True; False: in ``update`` itself, repeatable, for
    tests), reading the map (replaced, never changed in place), the scan's points and the
    parameters, and its own caches; one search at a time. A search running at cleanup or at
    exit ends on its own (a few seconds on a large map). Exceptions: configure fails naming a
    bad parameter; a failed search is a warning, the correction goes on.
    """

    PARAMETERS = _replace(
        CostmapAMCLLocalizer.PARAMETERS,
        Param("num_particles", 100, "accepted (costmap AMCL files); each hypothesis starts "
              "with max_particles", ge=1),
        Param("min_particles", 30, "fewest particles of a hypothesis (and KLD lower bound)",
              ge=1),
        Param("max_particles", 200, "most particles of a hypothesis (and KLD upper bound); a "
              "new hypothesis starts with this many", ge=1),
        Param("reseed_freq", 0.33, "reseed of every hypothesis at this rate", "Hz", gt=0.0),
        Param("recovery_alpha_slow", 0.0, "accepted (costmap AMCL files), not used: new "
              "hypotheses are the recovery", ge=0.0, le=1.0),
        Param("recovery_alpha_fast", 0.0, "accepted (costmap AMCL files), not used: new "
              "hypotheses are the recovery", ge=0.0, le=1.0),
        Param("recovery_sensor_resetting", True, "accepted (costmap AMCL files), not used: the "
              "hypotheses search does the same"),
        Param("global_localization", False, "one hypothesis per place where the scan fits the "
              "map (at configure, or when set true at runtime)"),
        # The original MH-AMCL's parameters (its README).
        Param("multihypothesis", True, "false: one hypothesis only (plain AMCL)"),
        Param("max_hypotheses", 5, "most hypotheses kept at once", ge=1),
        Param("hypotheses_freq", 0.33, "new hypotheses searched at this rate", "Hz", gt=0.0),
        Param("min_candidate_weight", 0.5, "least quality of a place to start a hypothesis",
              ge=0.0, le=1.0),
        Param("min_candidate_distance", 1.0, "a candidate this close (and within "
              "min_candidate_angle) to a hypothesis starts none", "m", ge=0.0),
        Param("min_candidate_angle", 1.5708, "see min_candidate_distance", "rad", ge=0.0),
        Param("new_hypothesis_std_xy", 0.1, "spread of a new hypothesis' particles", "m",
              gt=0.0),
        Param("new_hypothesis_std_yaw", 0.1, "spread of a new hypothesis' particles", "rad",
              gt=0.0),
        Param("low_q_hypo_threshold", 0.25, "below it a hypothesis grows its cloud and may be "
              "replaced when max_hypotheses are kept", ge=0.0, le=1.0),
        Param("very_low_q_hypo_threshold", 0.1, "below it a hypothesis is removed (not the "
              "last)", ge=0.0, le=1.0),
        Param("hypo_merge_distance", 0.3, "hypotheses this close (and within hypo_merge_angle) "
              "are merged", "m", ge=0.0),
        Param("hypo_merge_angle", 0.5, "see hypo_merge_distance", "rad", ge=0.0),
        Param("good_hypo_threshold", 0.6, "least quality to be published; above it the cloud "
              "shrinks", ge=0.0, le=1.0),
        Param("min_hypo_diff_winner", 0.2, "another hypothesis is published when the current "
              "one's accumulated likelihood is below (1 - this) of its", ge=0.0, lt=1.0),
        Param("matcher_levels", 4, _ACCEPTED.format(
            "the search is the costmap AMCL's"), ge=1),
        Param("matcher_angle_step", 0.3927, _ACCEPTED.format(
            "the search tries 36 headings"), "rad", gt=0.0),
        Param("particles_step", 30, "particles added (low quality) or removed (good quality) "
              "at each reseed", ge=0),
        Param("reseed_percentage_losers", 0.8, "share of each cloud redrawn at a reseed",
              ge=0.0, le=1.0),
        Param("reseed_percentage_winners", 0.03, "share of each cloud (the best) the redrawn "
              "particles are drawn around", gt=0.0, le=1.0),
        Param("reseed_noise_xy", 0.05, "σ of a redrawn particle around its parent", "m", gt=0.0),
        Param("reseed_noise_yaw", 0.05, "σ of a redrawn particle around its parent", "rad",
              gt=0.0),
        Param("distance_perception_error", 0.05, "σ of the sensor: quality counts points within "
              "3σ (at least one map cell) of an obstacle; hit_count weighs exp(-d²/2σ²)", "m",
              gt=0.0),
        Param("correct_max_points", 500, "most scan points per correction (evenly picked)",
              ge=1),
        Param("min_height", 0.1, "points at or below it (footprint frame) are the floor", "m"),
        Param("odom_key", "odom", _ACCEPTED.format(
            "the odometry is the 'odom' topic, or TF with compute_odom_from_tf")),
        # Beyond the original.
        Param("hypo_prune_ratio", 0.01, "a hypothesis whose accumulated likelihood falls below "
              "this share of the best's is removed" + _NOT_ORIGINAL, gt=0.0, lt=1.0),
        Param("new_hypothesis_ratio", 0.1, "a new hypothesis starts with this share of the "
              "best's accumulated likelihood (times its quality ratio)" + _NOT_ORIGINAL,
              gt=0.0, le=1.0),
        Param("hypo_likelihood_decay", 1.0, "accumulated log-likelihoods are multiplied by this "
              "before each correction (1: none forgotten)" + _NOT_ORIGINAL, gt=0.0, le=1.0),
    )
    WRITES = (*CostmapAMCLLocalizer.WRITES, HYPOTHESES_COUNT)

    def __init__(self) -> None:
        super().__init__()
        self.hypotheses: list[Hypothesis] = []
        self.selected: Hypothesis | None = None
        self._next_ident = 0
        self._rng = np.random.default_rng()
        self._last_search = 0.0
        #: The hypotheses search runs in a thread of its own (False: in ``update``, which then
        #: waits for it; repeatable, for tests that seed the generator).
        self.search_in_background = True
        self._search_executor: ThreadPoolExecutor | None = None
        # The search running: its future, whether it is a global localisation, the odometry
        # of its scan.
        self._search_future: Future | None = None
        self._search_global = False
        self._search_odom = None
        self._search_epoch = 0  # a pose reset discards the search running (its epoch is older)
        self._search_started_epoch = 0
        self._mh_fields_key: tuple | None = None
        self._weight_field: np.ndarray | None = None
        self._quality_field: np.ndarray | None = None

    # -- configuration ------------------------------------------------------------------------
    def on_cleanup(self) -> None:
        """Stop the search thread (a search running is abandoned), then the base class's."""
        executor, self._search_executor = self._search_executor, None
        self._search_future = None
        if executor is not None:
            executor.shutdown(wait=False, cancel_futures=True)
        super().on_cleanup()

    def on_deactivate(self) -> None:
        """A search running is dropped: its scan is from before the pause."""
        self._search_epoch += 1
        super().on_deactivate()

    def on_initialize(self) -> None:
        p = self.params
        alias = self.plugin_name
        if p.min_particles > p.max_particles:
            raise PluginConfigurationError(
                f"{alias}.min_particles = {p.min_particles} exceeds {alias}.max_particles = "
                f"{p.max_particles}")
        if p.very_low_q_hypo_threshold > p.low_q_hypo_threshold:
            raise PluginConfigurationError(
                f"{alias}.very_low_q_hypo_threshold = {p.very_low_q_hypo_threshold} exceeds "
                f"{alias}.low_q_hypo_threshold = {p.low_q_hypo_threshold}")
        super().on_initialize()
        self._mh_fields_key = None
        self._last_search = self.now()
        with self._lock:
            self.hypotheses = []
            self._start_hypothesis(
                (p["initial_pose.x"], p["initial_pose.y"], p["initial_pose.yaw"]),
                p["initial_pose.std_dev_xy"], p["initial_pose.std_dev_yaw"], 0.0)
            self._select(self.hypotheses[0])
        self.logger.info(
            f"{alias}: multi-hypothesis AMCL: one hypothesis of {p.max_particles} particles to "
            f"start, at most {p.max_hypotheses}" + ("" if p.multihypothesis else
                                                    " (multihypothesis off: one)"))

    @property
    def rng(self) -> np.random.Generator:
        """The random generator of every hypothesis (set it for repeatable runs)."""
        return self._rng

    @rng.setter
    def rng(self, rng: np.random.Generator) -> None:
        with self._lock:
            self._rng = rng
            for h in self.hypotheses:
                h.filter.rng = rng

    def _start_hypothesis(self, pose, std_xy: float, std_yaw: float,
                          log_likelihood: float, quality: float | None = None) -> Hypothesis:
        """A new hypothesis of ``max_particles`` around ``pose`` (lock held)."""
        cloud = ParticleFilter2D(int(self.params.max_particles), self._rng)
        cloud.seed(pose[0], pose[1], pose[2], np.eye(2) * std_xy**2, std_yaw,
                   self.min_noise_xy, self.min_noise_yaw)
        hypothesis = Hypothesis(self._next_ident, cloud, log_likelihood, quality)
        self._next_ident += 1
        self.hypotheses.append(hypothesis)
        return hypothesis

    def _select(self, hypothesis: Hypothesis) -> None:
        self.selected = hypothesis
        self.filter = hypothesis.filter  # what the shared code (pose, particles) reads

    def reset_pose(self, x: float, y: float, yaw: float, cov_xy: np.ndarray,
                   var_yaw: float) -> None:
        """Discard every hypothesis and start one around ``(x, y, yaw)`` with that covariance
        (``initialpose``, the previous localizer's pose). Any non-RT thread."""
        with self._lock:
            self._generation += 1
            self.hypotheses = []
            h = self._start_hypothesis((x, y, yaw), 0.0, math.sqrt(max(var_yaw, 0.0)), 0.0)
            h.filter.seed(x, y, yaw, cov_xy, math.sqrt(max(var_yaw, 0.0)),
                          self.min_noise_xy, self.min_noise_yaw)
            self._select(h)
            # The pose given now wins over a search running (a global one's above all) and a
            # global localisation requested before and still waiting for its search.
            self._search_epoch += 1
            self._global_requested = False
        self._last_reseed = self._last_search = self.now()
        self.logger.info(f"{self.plugin_name}: hypotheses reset to one around "
                         f"({x:.3f}, {y:.3f}, {yaw:.3f})")

    # -- prediction (RT) ----------------------------------------------------------------------
    def _predict(self, dx: float, dy: float, dyaw: float) -> None:
        """Move every hypothesis by an odometry increment (the base class's update_rt then
        writes the selected one's pose and ``map → odom``). RT thread, lock held."""
        for h in self.hypotheses:
            h.filter.predict(dx, dy, dyaw, *self.noise)

    # -- correction (non-RT) ------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Weigh every hypothesis, reseed, search for new ones when due, merge, prune, select;
        write the selected one's pose. Non-RT thread."""
        base = self._map_for_update(nav_state)
        if base is None:
            return
        points = self._scan_points(nav_state, base.resolution)
        if points is None:
            return
        p = self.params
        weight_field, quality_field = self._fields(base)
        with self._lock:
            hypotheses = list(self.hypotheses)
            snapshot = [h.filter.poses.copy() for h in hypotheses]
            generation = self._generation
            odom_at_scan = self._odom_used
            epoch = self._search_epoch
        sizes = [len(s) for s in snapshot]
        poses = np.concatenate(snapshot)
        if p.sensor_model == LIKELIHOOD_FIELD:
            likelihoods, _ = self._likelihood_field_weights(poses, points, base)
        else:
            likelihoods, _ = hit_fractions(poses, points, base, weight_field)
        qualities = self._qualities(base, poses, points, quality_field)
        now = self.now()
        candidates, global_now, odom_at_search = self._search_step(
            base, points, quality_field, now, odom_at_scan, epoch)
        reseed_due = now - self._last_reseed >= self.reseed_period or now < self._last_reseed
        with self._lock:
            if generation == self._generation and hypotheses == self.hypotheses:
                self._correct(hypotheses, sizes, likelihoods, qualities)
                if reseed_due:
                    for h in self.hypotheses:
                        self._reseed_hypothesis(h)
                    self._last_reseed = now
                if candidates is not None:
                    candidates = self._moved(candidates, odom_at_search)
                    if global_now:
                        self._restart_from(candidates)
                    else:
                        self._add_from(candidates)
                self._merge()
                self._prune(base)
                self._choose()
            estimate = self.filter.estimate()
            covariance = self.filter.covariance(estimate)
            particles = self.filter.poses.copy()
            count = len(self.hypotheses)
        self._write_pose(nav_state, estimate, covariance, self._odom)
        nav_state.set(HYPOTHESES_COUNT, count)
        self._publish_particles(particles, estimate, covariance)

    def _scan_points(self, nav_state: NavState, resolution: float) -> np.ndarray | None:
        """The fused points above ``min_height`` in the footprint frame, downsampled to the map
        resolution, at most ``correct_max_points`` (evenly picked), as ``(N, 2)``."""
        perceptions = nav_state.get_no_group(PointPerception)
        if not perceptions:
            self._throttle.warn(self.logger, "no-perceptions",
                                f"{self.plugin_name}: no point perceptions")
            return None
        buffer = get_tf_buffer(self.context.namespace)
        frame = buffer.get_tf_info().robot_footprint_frame
        min_height = self.params.min_height
        points = (
            PointPerceptionsOps(perceptions, buffer, self.logger)
            .fuse(frame)
            .filter((math.nan, math.nan, min_height), (math.nan, math.nan, math.nan))
            .collapse((math.nan, math.nan, 0.0))
            .downsample(resolution)
            .as_points()
        )
        if len(points) == 0:
            self._throttle.warn(self.logger, "no-points", f"{self.plugin_name}: no points to "
                                f"correct with (none above z {min_height} m in {frame})")
            return None
        limit = int(self.params.correct_max_points)
        if len(points) > limit:
            points = points[np.linspace(0, len(points) - 1, limit).astype(int)]
        return points[:, :2]

    def _fields(self, base: Costmap2D) -> tuple[np.ndarray, np.ndarray]:
        """The soft hit field (σ ``distance_perception_error``, at least a third of a cell;
        zero beyond 3σ) and the quality field (1 within 3σ of a lethal surface cell,
        :func:`surface_cells`), cached per map object and σ."""
        sigma = float(self.params.distance_perception_error)
        key = (base, sigma)  # map.base is replaced, never mutated: cache per object
        if (self._mh_fields_key is None or self._mh_fields_key[0] is not base
                or self._mh_fields_key[1] != sigma):
            obstacles = surface_cells(base)
            if obstacles.any():
                free = (~obstacles).astype(np.uint8)
                d = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
                d = d * base.resolution
            else:
                d = np.full(obstacles.shape, np.inf, dtype=np.float32)
            # At least a third of a cell: on a map coarser than 3σ, a point measured on an
            # obstacle's surface falls in the free cell beside it about half the time (the
            # grid's error, not the sensor's), and counted as a miss it ranked look-alike
            # places above the true one (the campus' 0.2 m map: quality 0.55-0.63 at the true
            # pose, 0.86-0.94 along another fence, which took over after 20 s).
            sigma = max(sigma, base.resolution / 3.0)
            near = d <= 3.0 * sigma * (1.0 + 1e-6)  # one cell away counts, float32 or not
            self._weight_field = np.where(near, np.exp(-0.5 * np.square(d / sigma)),
                                          0.0).astype(np.float32)
            self._quality_field = near.astype(np.float32)
            self._mh_fields_key = key
        return self._weight_field, self._quality_field

    @staticmethod
    def _qualities(base, poses, points, quality_field) -> np.ndarray:
        """Each pose's share of the scan near an obstacle (``quality_field``; points off the
        map miss)."""
        fractions, inside = hit_fractions(poses, points, base, quality_field)
        return fractions * inside / len(points)

    def _correct(self, hypotheses, sizes, likelihoods, qualities) -> None:
        """Weigh each hypothesis, resample degenerate clouds, update qualities and the
        accumulated log-likelihoods (lock held)."""
        p = self.params
        start = 0
        for h, n in zip(hypotheses, sizes, strict=True):
            weights = likelihoods[start:start + n]
            quality = float(qualities[start:start + n].max())
            start += n
            if h.filter.correct(weights) and (
                    h.filter.effective_sample_size() < 0.5 * len(h.filter)):
                count = None
                if p.kld_sampling:
                    count = kld_particle_count(h.filter.poses, p.pf_err, p.pf_z,
                                               p.min_particles, p.max_particles)
                h.filter.resample(count)
            h.quality = quality if h.quality is None else (
                (1.0 - _QUALITY_SMOOTHING) * h.quality + _QUALITY_SMOOTHING * quality)
            h.log_likelihood = (p.hypo_likelihood_decay * h.log_likelihood
                                + math.log(max(quality, _MIN_QUALITY)))
        self._normalise_likelihoods()

    def _normalise_likelihoods(self) -> None:
        if self.hypotheses:
            top = max(h.log_likelihood for h in self.hypotheses)
            for h in self.hypotheses:
                h.log_likelihood -= top

    def _reseed_hypothesis(self, h: Hypothesis) -> None:
        """The original's reseed: resize by ``particles_step`` from the quality, then redraw the
        losers around the winners (lock held)."""
        p = self.params
        cloud = h.filter
        n = len(cloud)
        quality = h.quality if h.quality is not None else 0.0
        target = n
        if not p.kld_sampling:
            if quality < p.low_q_hypo_threshold:
                target = n + p.particles_step
            elif quality > p.good_hypo_threshold:
                target = n - p.particles_step
            target = int(min(max(target, p.min_particles), p.max_particles))
        if target != n:
            cloud.resample(target)
            n = target
        losers = int(round(p.reseed_percentage_losers * n))
        winners = max(1, int(round(p.reseed_percentage_winners * n)))
        if losers == 0 or winners >= n:
            return
        losers = min(losers, n - winners)
        order = np.argsort(-cloud.weights, kind="stable")
        top, worst = order[:winners], order[n - losers:]
        top_w = cloud.weights[top] / cloud.weights[top].sum()
        picks = top[cloud.rng.choice(len(top), size=losers, p=top_w)]
        noise = cloud.rng.standard_normal((losers, 3))
        cloud.poses[worst, :2] = cloud.poses[picks, :2] + p.reseed_noise_xy * noise[:, :2]
        cloud.poses[worst, 2] = (cloud.poses[picks, 2] + p.reseed_noise_yaw * noise[:, 2]
                                 + math.pi) % (2.0 * math.pi) - math.pi
        cloud.weights[worst] = cloud.weights[picks]
        cloud.weights /= cloud.weights.sum()

    # -- hypotheses management ----------------------------------------------------------------
    def _search_step(self, base: Costmap2D, points: np.ndarray, quality_field: np.ndarray,
                     now: float, odom_at_scan, epoch: int):
        """Start a hypotheses search when one is due and none runs; return the candidates of
        the search that ended, if any: ``(candidates or None, global localisation?, odometry
        of its scan)``. ``epoch``: the search epoch when the scan was taken. Non-RT thread,
        outside the lock."""
        p = self.params
        candidates, global_search, odom_at_search = None, False, None
        future = self._search_future
        if future is not None and future.done():
            self._search_future = None
            if self._search_started_epoch == self._search_epoch:
                candidates, global_search, odom_at_search = (
                    self._search_result(future), self._search_global, self._search_odom)
        due = self._global_requested or (p.multihypothesis and (
            now - self._last_search >= 1.0 / p.hypotheses_freq or now < self._last_search))
        if due and self._search_future is None:
            global_now, self._global_requested = self._global_requested, False
            self._last_search = now
            if self.search_in_background:
                if self._search_executor is None:
                    self._search_executor = ThreadPoolExecutor(
                        max_workers=1, thread_name_prefix=f"{self.plugin_name}_search")
                # Its own generator: numpy's are not for two threads at once.
                rng = np.random.default_rng(self._rng.integers(2**63))
                self._search_future = self._search_executor.submit(
                    self._search, base, points, quality_field, rng)
                self._search_global, self._search_odom = global_now, odom_at_scan
                self._search_started_epoch = epoch
            elif candidates is None:
                candidates = self._search(base, points, quality_field, self._rng)
                global_search, odom_at_search = global_now, odom_at_scan
        return candidates, global_search, odom_at_search

    def _search_result(self, future: Future):
        """The candidates of a search that ended; None (and a warning) when it raised: the
        correction goes on without them."""
        try:
            return future.result()
        except Exception as exc:
            kind = "global localisation" if self._search_global else "hypotheses search"
            self._throttle.warn(self.logger, "search-failed",
                                f"{self.plugin_name}: {kind} failed, no new hypotheses: "
                                f"{type(exc).__name__}: {exc}")
            return None

    def _search(self, base: Costmap2D, points: np.ndarray, quality_field: np.ndarray,
                rng: np.random.Generator) -> list[tuple[np.ndarray, float]]:
        """Clusters of the poses where the scan fits the map, best first: ``(pose, quality)``
        of each cluster's best pose, quality at least ``min_candidate_weight``. The search
        thread (or ``update``'s), outside the lock; the compiled scoring releases the GIL."""
        p = self.params
        if base is not self._reset_map:
            self._reset_fields = (likelihood_field(base, RESET_STRIDE),
                                  likelihood_field(base, RESET_FINE_SIGMA))
            self._reset_map = base
        try:
            cloud = sensor_reset_poses(base, points, RESET_REFINED, rng,
                                       *self._reset_fields, spread=(0.0, 0.0))
        except ValueError as exc:
            self._throttle.warn(self.logger, "no-search",
                                f"{self.plugin_name}: no hypotheses search: {exc}")
            return []
        qualities = self._qualities(base, cloud, points, quality_field)
        return cluster_poses(cloud, qualities, p.min_candidate_distance,
                             p.min_candidate_angle, p.min_candidate_weight)

    def _moved(self, candidates, odom_at_scan):
        """The candidates carried by the odometry received since the scan (lock held)."""
        if odom_at_scan is None or self._odom_used is None or not candidates:
            return candidates
        poses = moved_by_increment(np.array([pose for pose, _ in candidates]),
                                   odometry_increment(odom_at_scan, self._odom_used))
        return [(pose, quality) for pose, (_, quality) in zip(poses, candidates, strict=True)]

    def _restart_from(self, candidates) -> None:
        """Global localisation: one hypothesis per cluster, all even (lock held)."""
        p = self.params
        if not candidates:
            self.logger.warning(f"{self.plugin_name}: global localisation: no place of the "
                                f"map fits the scan (min_candidate_weight "
                                f"{p.min_candidate_weight}); hypotheses kept")
            return
        self._generation += 1
        self.hypotheses = []
        for pose, quality in candidates[: int(p.max_hypotheses) if p.multihypothesis else 1]:
            self._start_hypothesis(pose, p.new_hypothesis_std_xy, p.new_hypothesis_std_yaw,
                                   0.0, quality)
        self._select(self.hypotheses[0])
        self.logger.info(
            f"{self.plugin_name}: global localisation: {len(self.hypotheses)} hypotheses at "
            + ", ".join(f"({h.estimate()[0]:.2f}, {h.estimate()[1]:.2f})"
                        for h in self.hypotheses))

    def _add_from(self, candidates) -> None:
        """Start a hypothesis at each candidate far from every hypothesis (lock held)."""
        p = self.params
        for pose, quality in candidates:
            if any(_close(pose, h.estimate(), p.min_candidate_distance, p.min_candidate_angle)
                   for h in self.hypotheses):
                continue
            if len(self.hypotheses) >= p.max_hypotheses:
                worst = min((h for h in self.hypotheses if h is not self.selected),
                            key=lambda h: h.log_likelihood, default=None)
                if worst is None or (worst.quality or 0.0) >= p.low_q_hypo_threshold:
                    continue
                self._remove(worst, "replaced by a new one")
            best = max(self.hypotheses, key=lambda h: h.log_likelihood)
            start = (best.log_likelihood + math.log(p.new_hypothesis_ratio)
                     + math.log(max(quality, _MIN_QUALITY))
                     - math.log(max(best.quality or 1.0, _MIN_QUALITY)))
            h = self._start_hypothesis(pose, p.new_hypothesis_std_xy, p.new_hypothesis_std_yaw,
                                       min(start, best.log_likelihood), quality)
            self._generation += 1
            self.logger.info(f"{self.plugin_name}: new hypothesis #{h.ident} at "
                             f"({pose[0]:.2f}, {pose[1]:.2f}, {pose[2]:.2f}), quality "
                             f"{quality:.2f}")

    def _remove(self, h: Hypothesis, why: str) -> None:
        self.hypotheses.remove(h)
        self._generation += 1
        x, y, _ = h.estimate()
        self.logger.debug(f"{self.plugin_name}: hypothesis #{h.ident} at ({x:.2f}, {y:.2f}) "
                          f"removed: {why}")

    def _merge(self) -> None:
        """Hypotheses that converged to one pose become the more likely one (lock held)."""
        p = self.params
        merged = True
        while merged and len(self.hypotheses) > 1:
            merged = False
            estimates = [h.estimate() for h in self.hypotheses]
            for i in range(len(self.hypotheses)):
                for j in range(i + 1, len(self.hypotheses)):
                    if _close(estimates[i], estimates[j], p.hypo_merge_distance,
                              p.hypo_merge_angle):
                        a, b = self.hypotheses[i], self.hypotheses[j]
                        keep, drop = (a, b) if a.log_likelihood >= b.log_likelihood else (b, a)
                        self._remove(drop, f"merged into #{keep.ident}")
                        merged = True
                        break
                if merged:
                    break

    def _prune(self, base: Costmap2D) -> None:
        """Remove the unlikely, the very low quality and the out-of-free-space (lock held)."""
        p = self.params
        floor = math.log(p.hypo_prune_ratio)
        self._normalise_likelihoods()
        for h in sorted(self.hypotheses, key=lambda h: h.log_likelihood):
            if len(self.hypotheses) == 1:
                break
            x, y, _ = h.estimate()
            if h.log_likelihood < floor:
                self._remove(h, f"likelihood ratio {math.exp(h.log_likelihood):.2g} to the best")
            elif h.quality is not None and h.quality < p.very_low_q_hypo_threshold:
                self._remove(h, f"quality {h.quality:.2f}")
            elif int(base.cost_at(np.array([x]), np.array([y]), outside=255)[0]) >= _NOT_FREE:
                self._remove(h, "out of the free space")
        self._normalise_likelihoods()

    def _choose(self) -> None:
        """Keep the published hypothesis unless another is clearly more likely (lock held)."""
        p = self.params
        current = self.selected if self.selected in self.hypotheses else None
        eligible = [h for h in self.hypotheses
                    if h.quality is not None and h.quality >= p.good_hypo_threshold]
        pool = eligible or ([] if current is not None else self.hypotheses)
        if not pool:
            return
        best = max(pool, key=lambda h: h.log_likelihood)
        if best is current:
            return
        margin = -math.log(1.0 - p.min_hypo_diff_winner)
        if current is not None and best.log_likelihood - current.log_likelihood <= margin:
            return
        x, y, yaw = best.estimate()
        if current is not None:
            ox, oy, _ = current.estimate()
            ratio = math.exp(min(best.log_likelihood - current.log_likelihood, 700.0))
            self.logger.info(
                f"{self.plugin_name}: switched from hypothesis #{current.ident} at ({ox:.2f}, "
                f"{oy:.2f}) to #{best.ident} at ({x:.2f}, {y:.2f}, {yaw:.2f}): likelihood ratio "
                f"{ratio:.3g}, quality {best.quality:.2f}")
        else:
            self.logger.info(f"{self.plugin_name}: hypothesis #{best.ident} at ({x:.2f}, "
                             f"{y:.2f}, {yaw:.2f}) published")
        self._select(best)


def _close(a, b, distance: float, angle: float) -> bool:
    return (math.hypot(a[0] - b[0], a[1] - b[1]) < distance
            and abs(normalize_angle(a[2] - b[2])) < angle)


def cluster_poses(poses: np.ndarray, qualities: np.ndarray, distance: float, angle: float,
                  min_quality: float) -> list[tuple[np.ndarray, float]]:
    """Greedy clustering, best first: a pose within ``distance`` and ``angle`` of a better
    cluster's head joins it; the heads scoring at least ``min_quality`` are returned as
    ``(pose, quality)``, best first."""
    heads: list[tuple[np.ndarray, float]] = []
    for i in np.argsort(-qualities, kind="stable"):
        if qualities[i] < min_quality:
            break
        if any(_close(poses[i], head, distance, angle) for head, _ in heads):
            continue
        heads.append((np.array(poses[i], dtype=float), float(qualities[i])))
    return heads
