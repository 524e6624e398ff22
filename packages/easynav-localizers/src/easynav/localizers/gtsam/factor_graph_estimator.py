"""FactorGraphEstimator: planar pose by fixed-lag smoothing (GTSAM iSAM2) of odometry, IMU yaw
and GNSS positions."""

from __future__ import annotations

import bisect
import math
from collections import deque

import numpy as np

#: Sigma standing for "not measured" in a Pose2 prior (x, y or theta left free).
_FREE = 1e6

#: What GTSAM raises for its internal failures (C++ std::out_of_range, std::invalid_argument
#: and the rest, through its Python wrapper).
_GTSAM_ERRORS = (RuntimeError, ValueError, IndexError)

#: Largest variances (x, y in m², yaw in rad²) of a graph anchored again after a failure.
_RECOVERY_VARIANCE_CAP = np.array((1e4, 1e4, math.pi**2))


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
    - :meth:`add_gnss`: a position-only prior, with a robust noise model (``robust``:
      ``cauchy``, ``huber``, ``tukey`` or ``none``, scale ``robust_k`` in σ units): a jump of
      many σ gets (almost) no weight. A fix stamped at or after the last odometry makes a
      keyframe of its own. A **late** fix (stamped before the last odometry: a GNSS driver
      behind the wheels) goes on the keyframe nearest its stamp, or on a new keyframe at the
      last odometry when it is newer than the last keyframe, its position moved by the
      odometry between its stamp and that keyframe's. Keyframe stamps only grow: iSAM2's
      fixed-lag marginalisation breaks for good on one stamped back in time. A late fix older
      than the window's keyframes (or than the odometry kept) is dropped (``gnss_dropped``).
    - :meth:`pose` is the last keyframe's estimate composed with the odometry since;
      :meth:`covariance` the last keyframe's marginal covariance.

    The first GNSS fix (or :meth:`reset`) anchors the graph; before that there is no estimate.
    Should GTSAM raise in an update, the graph is anchored again at the estimate the update
    would have refined, its variances doubled (capped): ``solver_failures`` counts it and
    ``last_failure`` says what GTSAM said, so the plugin can warn; the measurements of that
    update are lost, the next ones go on as after a reset.
    Raises ImportError naming the extra when gtsam is missing, ValueError when ``lag`` is
    shorter than two keyframe periods. Thread contract: none (the plugin serialises calls).
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
        if lag < 2.0 * keyframe_period:
            raise ValueError(f"lag ({lag} s) must be at least two keyframe periods "
                             f"(keyframe_period {keyframe_period} s)")
        self._g = gtsam
        # GTSAM 4.3 has the fixed-lag smoother in gtsam; 4.2 (Python 3.10) in gtsam_unstable.
        unstable = gtsam
        if not hasattr(gtsam, "IncrementalFixedLagSmoother"):
            import gtsam_unstable as unstable
        self._smoother_class = unstable.IncrementalFixedLagSmoother
        self._stamps_class = unstable.FixedLagSmootherKeyTimestampMap
        self.lag = lag
        self.keyframe_period = keyframe_period
        self.odom_sigma_xy, self.odom_sigma_yaw = odom_sigma_xy, odom_sigma_yaw
        self.odom_sigma_min = odom_sigma_min
        self.robust, self.robust_k = robust, robust_k
        self._smoother = self._smoother_class(lag, gtsam.ISAM2Params())
        self._k = -1  # index of the last keyframe
        self._key_time = 0.0
        self._estimate = None  # Pose2 of the last keyframe
        self._cov = np.eye(3)
        self._odom_last = None  # (x, y, yaw) of the odometry at the last message
        self._odom_stamp: float | None = None  # and its stamp
        # (stamp, x, y, yaw) of the odometry back to the window's start: where a late fix was
        self._odom_history: deque[tuple[float, float, float, float]] = deque()
        self._delta = gtsam.Pose2()  # odometry since the last keyframe
        self._travel = [0.0, 0.0]  # metres, radians since the last keyframe
        self._pending_yaw: tuple[float, float] | None = None
        # (stamp, index, odometry (x, y, yaw) or None) of the keyframes inside the window
        self._keyframes: deque[tuple[float, int, tuple | None]] = deque()
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
        if self._odom_history and stamp < self._odom_history[-1][0]:
            self._odom_history.clear()  # the clock went back: the history means nothing
        self._odom_stamp = stamp
        self._odom_history.append((stamp, x, y, yaw))
        while self._odom_history[0][0] < min(stamp, self._key_time) - self.lag - 1.0:
            self._odom_history.popleft()
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
        late = self._odom_stamp is not None and stamp < self._odom_stamp
        if late and stamp < self._key_time:
            self._add_to_past_keyframe(stamp, x, y, sigma_x, sigma_y, noise)
            return
        predicted = self._estimate.compose(self._delta)  # the robot at the last odometry
        if late:  # after the last keyframe: on a new one at the last odometry
            x, y = self._moved(x, y, self._odom_at(stamp), self._odom_last, predicted.theta())
            stamp = self._odom_stamp
        if self._keyframe(stamp, [g.PriorFactorPose2(g.symbol("x", self._k + 1),
                                                     g.Pose2(x, y, predicted.theta()), noise)]):
            self._count_gnss(x, y, sigma_x, sigma_y, predicted)

    def reset(self, stamp: float, x: float, y: float, yaw: float, covariance: np.ndarray) -> None:
        """Anchor (or re-anchor) the graph at ``(x, y, yaw)`` with a 3×3 covariance."""
        g = self._g
        smoother = self._smoother_class(self.lag, g.ISAM2Params())
        key = g.symbol("x", 0)
        sigmas = np.sqrt(np.maximum(np.diag(np.asarray(covariance, float)), 1e-8))
        graph = g.NonlinearFactorGraph()
        graph.add(g.PriorFactorPose2(key, g.Pose2(x, y, yaw), g.noiseModel.Diagonal.Sigmas(
            sigmas)))
        values = g.Values()
        values.insert(key, g.Pose2(x, y, yaw))
        stamps = self._stamps_class()
        stamps.insert((key, stamp))
        smoother.update(graph, values, stamps)
        self._smoother = smoother
        self._k = 0
        self._key_time = stamp
        self._keyframes = deque([(stamp, 0, self._odom_last)])
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
    def _keyframe(self, stamp: float, priors: list) -> bool:
        """A new keyframe at ``stamp`` (never before the last) with ``priors`` on it; False
        when GTSAM failed (the graph is anchored again)."""
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
        for prior in priors:
            graph.add(prior)
        values = g.Values()
        values.insert(key, guess)
        stamps = self._stamps_class()
        stamps.insert((key, stamp))
        try:
            self._smoother.update(graph, values, stamps)
            estimate, cov = self._solution(key)
        except _GTSAM_ERRORS as exc:
            self._recover(stamp, guess, exc)
            return False
        self._k += 1
        self._key_time = stamp
        self._keyframes.append((stamp, self._k, self._odom_last))
        while self._keyframes[0][0] < stamp - self.lag:  # marginalised by this update
            self._keyframes.popleft()
        self._estimate, self._cov = estimate, cov
        self._delta = g.Pose2()
        self._travel = [0.0, 0.0]
        return True

    def _add_to_past_keyframe(self, stamp: float, x: float, y: float, sigma_x: float,
                              sigma_y: float, noise) -> None:
        """A fix older than the last keyframe: a prior on the keyframe nearest its stamp among
        those the update keeps (it adds no key, so nothing more is marginalised)."""
        g = self._g
        oldest = self._key_time - self.lag + self.keyframe_period  # clear of marginalisation
        kept = [(ks, k, odom) for ks, k, odom in self._keyframes if ks >= oldest]
        at_fix = self._odom_at(stamp)
        if not kept or at_fix is None or stamp < kept[0][0] - self.keyframe_period:
            self.gnss_dropped += 1  # older than the window (or the odometry kept)
            return
        _, index, odom = min(kept, key=lambda frame: abs(frame[0] - stamp))
        key, last = g.symbol("x", index), g.symbol("x", self._k)
        try:
            at_key = self._solution(key)[0]
            x, y = self._moved(x, y, at_fix, odom, at_key.theta())
            graph = g.NonlinearFactorGraph()
            graph.add(g.PriorFactorPose2(key, g.Pose2(x, y, at_key.theta()), noise))
            self._smoother.update(graph, g.Values(), self._stamps_class())
            estimate, cov = self._solution(last)
        except _GTSAM_ERRORS as exc:
            self._recover(self._key_time, self._estimate.compose(self._delta), exc)
            return
        self._count_gnss(x, y, sigma_x, sigma_y, at_key)
        self._estimate, self._cov = estimate, cov

    def _solution(self, key) -> tuple:
        """The estimate (Pose2) of ``key`` and its 3×3 marginal covariance."""
        if hasattr(self._smoother, "calculateEstimatePose2"):  # GTSAM 4.3
            estimate = self._smoother.calculateEstimatePose2(key)
        else:  # 4.2: the whole window's Values
            estimate = self._smoother.calculateEstimate().atPose2(key)
        return estimate, np.asarray(self._smoother.getISAM2().marginalCovariance(key))

    def _odom_at(self, stamp: float) -> tuple[float, float, float] | None:
        """The odometry pose at ``stamp``, interpolated; None before the history kept."""
        history = self._odom_history
        if not history or stamp < history[0][0]:
            return None
        stamps = [h[0] for h in history]
        i = bisect.bisect_left(stamps, stamp)
        if i == len(history):
            return history[-1][1:]
        t1, x1, y1, yaw1 = history[i]
        if i == 0 or t1 == stamp:
            return x1, y1, yaw1
        t0, x0, y0, yaw0 = history[i - 1]
        f = (stamp - t0) / (t1 - t0)
        return (x0 + f * (x1 - x0), y0 + f * (y1 - y0), yaw0 + f * _wrap(yaw1 - yaw0))

    def _moved(self, x: float, y: float, at_fix, at_key, key_yaw: float) -> tuple[float, float]:
        """The fix's position ``(x, y)`` moved to where the keyframe's robot was: minus the
        odometry from the keyframe to the fix (``at_key`` → ``at_fix``), turned by the
        keyframe's estimated heading. Unmoved when either odometry pose is unknown."""
        if at_fix is None or at_key is None:
            return x, y
        g = self._g
        step = g.Pose2(*at_key).between(g.Pose2(*at_fix))
        c, s = math.cos(key_yaw), math.sin(key_yaw)
        return x - (c * step.x() - s * step.y()), y - (s * step.x() + c * step.y())

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
        variances = np.minimum(2.0 * np.diag(self._cov), _RECOVERY_VARIANCE_CAP)
        self.reset(max(stamp, self._key_time), keyframe.x(), keyframe.y(), keyframe.theta(),
                   np.diag(variances))
