"""FactorGraphEstimator: planar pose by fixed-lag smoothing (GTSAM iSAM2) of odometry, IMU yaw
and GNSS positions."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

#: Sigma standing for "not measured" in a Pose2 prior (x, y or theta left free).
_FREE = 1e6


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class FactorGraphEstimator:
    """Poses ``X(k)`` (Pose2) at keyframes, solved by GTSAM's IncrementalFixedLagSmoother (iSAM2
    over a sliding window of ``lag`` seconds, older poses marginalised: the cost stays flat).

    - :meth:`add_odometry` accumulates the odometry increment; a new keyframe is made when a
      GNSS fix arrives or ``keyframe_period`` has passed, joined to the previous one by a
      ``BetweenFactorPose2`` of that increment (σ: ``odom_sigma_xy`` per metre and
      ``odom_sigma_yaw`` per radian travelled, at least ``odom_sigma_min``).
    - :meth:`add_imu_yaw`: the latest IMU heading becomes a yaw-only prior on the next keyframe.
    - :meth:`add_gnss`: a position-only prior on a new keyframe, with a robust noise model
      (``robust``: ``cauchy``, ``huber``, ``tukey`` or ``none``, scale ``robust_k`` in σ units):
      a jump of many σ gets (almost) no weight. A fix stamped before the last keyframe (a GNSS
      driver late against the odometry) goes on the keyframe nearest its stamp, the smoother's
      reason to be: keyframe stamps must only grow (iSAM2's fixed-lag marginalisation breaks for
      good on one that goes back). A late fix with no keyframe within ``keyframe_period`` of its
      stamp inside the window is dropped (``gnss_dropped``).
    - :meth:`pose` is the last keyframe's estimate composed with the odometry since;
      :meth:`covariance` the last keyframe's marginal covariance.

    The first GNSS fix (or :meth:`reset`) anchors the graph; before that there is no estimate.
    Should GTSAM still raise in an update, the graph is anchored again at the last estimate
    (covariance doubled): ``solver_failures`` counts it and ``last_failure`` says what GTSAM
    said, so the plugin can warn, and the next inputs go on as after a reset.
    Raises ImportError naming the extra when gtsam is missing. Thread contract: none (the
    plugin serialises calls).
    """

    def __init__(self, lag: float = 5.0, keyframe_period: float = 0.2,
                 odom_sigma_xy: float = 0.05, odom_sigma_yaw: float = 0.05,
                 odom_sigma_min: float = 0.005, robust: str = "cauchy",
                 robust_k: float = 3.0) -> None:
        try:
            import gtsam
        except ImportError as exc:  # an optional extra
            raise ImportError(
                "the GTSAM localizer needs gtsam: pip install easynav-localizers[gtsam]"
            ) from exc
        self._g = gtsam
        self.lag = lag
        self.keyframe_period = keyframe_period
        self.odom_sigma_xy, self.odom_sigma_yaw = odom_sigma_xy, odom_sigma_yaw
        self.odom_sigma_min = odom_sigma_min
        self.robust, self.robust_k = robust, robust_k
        params = gtsam.ISAM2Params()
        self._smoother = gtsam.IncrementalFixedLagSmoother(lag, params)
        self._k = -1  # index of the last keyframe
        self._key_time = 0.0
        self._estimate = None  # Pose2 of the last keyframe
        self._cov = np.eye(3)
        self._odom_last = None  # (x, y, yaw) of the odometry at the last message
        self._delta = gtsam.Pose2()  # odometry since the last keyframe
        self._travel = [0.0, 0.0]  # metres, radians since the last keyframe
        self._pending_yaw: tuple[float, float] | None = None
        self._keyframes: deque[tuple[float, int]] = deque()  # (stamp, index) inside the window
        self.gnss_rejected = 0
        self.gnss_used = 0
        self.gnss_dropped = 0
        self.solver_failures = 0
        self.last_failure = ""

    # -- inputs --------------------------------------------------------------------------------
    @property
    def initialized(self) -> bool:
        """Whether the graph is anchored (first fix or reset)."""
        return self._k >= 0

    def add_odometry(self, stamp: float, x: float, y: float, yaw: float) -> None:
        """An odometry pose (odom frame); its increment since the previous one is kept."""
        g = self._g
        if self._odom_last is not None:
            ox, oy, oyaw = self._odom_last
            step = g.Pose2(ox, oy, oyaw).between(g.Pose2(x, y, yaw))
            self._delta = self._delta.compose(step)
            self._travel[0] += math.hypot(step.x(), step.y())
            self._travel[1] += abs(step.theta())
        self._odom_last = (x, y, yaw)
        if self.initialized and stamp - self._key_time >= self.keyframe_period:
            self._keyframe(stamp, [])

    def add_imu_yaw(self, yaw: float, sigma: float) -> None:
        """An absolute heading (rad, σ rad): a prior on the next keyframe's yaw."""
        self._pending_yaw = (yaw, max(sigma, 1e-3))

    def add_gnss(self, stamp: float, x: float, y: float, sigma_x: float, sigma_y: float) -> None:
        """A GNSS position (map frame, σ per axis): anchors the graph or adds a robust prior."""
        g = self._g
        if not self.initialized:
            yaw = self._pending_yaw[0] if self._pending_yaw is not None else 0.0
            yaw_sigma = self._pending_yaw[1] if self._pending_yaw is not None else math.pi
            self.reset(stamp, x, y, yaw, np.diag([sigma_x**2, sigma_y**2, yaw_sigma**2]))
            return
        noise = g.noiseModel.Diagonal.Sigmas(np.array((sigma_x, sigma_y, _FREE)))
        if self.robust != "none":
            estimator = {"cauchy": g.noiseModel.mEstimator.Cauchy,
                         "huber": g.noiseModel.mEstimator.Huber,
                         "tukey": g.noiseModel.mEstimator.Tukey}[self.robust]
            noise = g.noiseModel.Robust.Create(estimator.Create(self.robust_k), noise)
        if stamp < self._key_time:
            self._add_late_gnss(stamp, x, y, sigma_x, sigma_y, noise)
            return
        predicted = self._estimate.compose(self._delta)
        self._count_gnss(x, y, sigma_x, sigma_y, predicted)
        self._keyframe(stamp, [("prior", g.Pose2(x, y, predicted.theta()), noise)])

    def reset(self, stamp: float, x: float, y: float, yaw: float, covariance: np.ndarray) -> None:
        """Anchor (or re-anchor) the graph at ``(x, y, yaw)`` with a 3×3 covariance."""
        g = self._g
        self._smoother = g.IncrementalFixedLagSmoother(self.lag, g.ISAM2Params())
        self._k = 0
        key = g.symbol("x", 0)
        sigmas = np.sqrt(np.maximum(np.diag(np.asarray(covariance, float)), 1e-8))
        graph = g.NonlinearFactorGraph()
        graph.add(g.PriorFactorPose2(key, g.Pose2(x, y, yaw), g.noiseModel.Diagonal.Sigmas(
            sigmas)))
        values = g.Values()
        values.insert(key, g.Pose2(x, y, yaw))
        stamps = g.FixedLagSmootherKeyTimestampMap()
        stamps.insert((key, stamp))
        self._smoother.update(graph, values, stamps)
        self._key_time = stamp
        self._keyframes = deque([(stamp, 0)])
        self._estimate = g.Pose2(x, y, yaw)
        self._cov = np.diag(sigmas**2)
        self._delta = g.Pose2()
        self._travel = [0.0, 0.0]

    # -- outputs -------------------------------------------------------------------------------
    def pose(self) -> tuple[float, float, float] | None:
        """``(x, y, yaw)``: the last keyframe's estimate plus the odometry since."""
        if not self.initialized:
            return None
        p = self._estimate.compose(self._delta)
        return p.x(), p.y(), _wrap(p.theta())

    def covariance(self) -> np.ndarray:
        """3×3 marginal covariance (x, y, yaw) of the last keyframe."""
        return self._cov.copy()

    # -- internals -----------------------------------------------------------------------------
    def _keyframe(self, stamp: float, priors: list) -> None:
        g = self._g
        previous, key = g.symbol("x", self._k), g.symbol("x", self._k + 1)
        sx = max(self.odom_sigma_xy * self._travel[0], self.odom_sigma_min)
        syaw = max(self.odom_sigma_yaw * self._travel[1] + 0.01 * self._travel[0],
                   self.odom_sigma_min)
        graph = g.NonlinearFactorGraph()
        graph.add(g.BetweenFactorPose2(previous, key, self._delta,
                                       g.noiseModel.Diagonal.Sigmas(np.array((sx, sx, syaw)))))
        guess = self._estimate.compose(self._delta)
        if self._pending_yaw is not None:
            yaw, sigma = self._pending_yaw
            graph.add(g.PriorFactorPose2(key, g.Pose2(guess.x(), guess.y(), yaw),
                                         g.noiseModel.Diagonal.Sigmas(
                                             np.array((_FREE, _FREE, sigma)))))
            self._pending_yaw = None
        for _, pose, noise in priors:
            graph.add(g.PriorFactorPose2(key, pose, noise))
        values = g.Values()
        values.insert(key, guess)
        stamps = g.FixedLagSmootherKeyTimestampMap()
        stamps.insert((key, stamp))
        try:
            self._smoother.update(graph, values, stamps)
            estimate = self._smoother.calculateEstimatePose2(key)
            cov = np.asarray(self._smoother.marginalCovariance(key))
        except Exception as exc:  # GTSAM's internal errors: IndexError, ValueError, RuntimeError
            self._recover(stamp, guess, exc)
            return
        self._k += 1
        self._key_time = stamp
        self._keyframes.append((stamp, self._k))
        while self._keyframes[0][0] < stamp - self.lag:  # marginalised by this update
            self._keyframes.popleft()
        self._estimate, self._cov = estimate, cov
        self._delta = g.Pose2()
        self._travel = [0.0, 0.0]

    def _add_late_gnss(self, stamp: float, x: float, y: float, sigma_x: float, sigma_y: float,
                       noise) -> None:
        """A fix older than the last keyframe: a prior on the keyframe nearest its stamp among
        those the next update keeps (no new key, so nothing more is marginalised)."""
        g = self._g
        oldest = self._key_time - self.lag + self.keyframe_period  # clear of marginalisation
        near = [(abs(ks - stamp), k) for ks, k in self._keyframes if ks >= oldest]
        if not near or min(near)[0] > self.keyframe_period:
            self.gnss_dropped += 1
            return
        key = g.symbol("x", min(near)[1])
        last = g.symbol("x", self._k)
        try:
            at_fix = self._smoother.calculateEstimatePose2(key)
            self._count_gnss(x, y, sigma_x, sigma_y, at_fix)
            graph = g.NonlinearFactorGraph()
            graph.add(g.PriorFactorPose2(key, g.Pose2(x, y, at_fix.theta()), noise))
            self._smoother.update(graph, g.Values(), g.FixedLagSmootherKeyTimestampMap())
            estimate = self._smoother.calculateEstimatePose2(last)
            cov = np.asarray(self._smoother.marginalCovariance(last))
        except Exception as exc:  # GTSAM's internal errors, as in _keyframe
            self._recover(self._key_time, self._estimate.compose(self._delta), exc)
            return
        self._estimate, self._cov = estimate, cov

    def _count_gnss(self, x: float, y: float, sigma_x: float, sigma_y: float, predicted) -> None:
        # Counted (not decided) here: the robust kernel does the down-weighting in the solver.
        if math.hypot((x - predicted.x()) / sigma_x, (y - predicted.y()) / sigma_y) > \
                3.0 * self.robust_k:
            self.gnss_rejected += 1
        else:
            self.gnss_used += 1

    def _recover(self, stamp: float, keyframe, exc: Exception) -> None:
        """GTSAM raised: anchor a new graph at ``keyframe`` (the estimate the failed update
        would have refined), so one failure does not end localisation."""
        self.solver_failures += 1
        self.last_failure = f"{type(exc).__name__}: {exc}"
        self.reset(max(stamp, self._key_time), keyframe.x(), keyframe.y(), keyframe.theta(),
                   2.0 * self._cov)
