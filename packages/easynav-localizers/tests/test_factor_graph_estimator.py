"""FactorGraphEstimator (GTSAM fixed-lag smoothing) without ROS: tracking with GNSS noise, a
GNSS outage, GNSS jumps, GNSS fixes late against the odometry, a failing solver."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("gtsam")

from easynav.localizers.gtsam.factor_graph_estimator import FactorGraphEstimator  # noqa: E402

RATE = 10.0
GNSS_EVERY = 2  # 5 Hz
GNSS_SIGMA = 0.8
OUTAGE = (60.0, 90.0)
JUMP = (120.0, 122.0)


def simulate(duration=150.0, outage=OUTAGE, jump=JUMP, robust="cauchy", seed=0,
             max_delay=0.0):
    """A robot on a weaving course; ``max_delay``: each fix reaches the estimator up to that
    many seconds after its stamp (uniform), after the odometry of that time."""
    rng = np.random.default_rng(seed)
    delays = np.random.default_rng(seed + 1)  # the same noise whatever the delays
    in_flight = []  # (arrival, stamp, x, y) of the fixes not yet delivered
    est = FactorGraphEstimator(lag=5.0, keyframe_period=0.2, robust=robust)
    true = np.array((0.0, 0.0, 0.3))
    odom = np.array((0.0, 0.0, 0.3))
    dead = true.copy()  # odometry alone, aligned at the start
    log = []
    t = 0.0
    dt = 1.0 / RATE
    fix = (math.nan, math.nan)
    for k in range(int(duration * RATE)):
        v, w = 1.0, 0.35 * math.sin(2 * math.pi * t / 40.0)
        true += (v * math.cos(true[2]) * dt, v * math.sin(true[2]) * dt, w * dt)
        t += dt
        v_o, w_o = 1.03 * v + rng.normal(0, 0.02), w + 0.02 + rng.normal(0, 0.01)
        odom += (v_o * math.cos(odom[2]) * dt, v_o * math.sin(odom[2]) * dt, w_o * dt)
        dead = odom.copy()
        est.add_imu_yaw(true[2] + rng.normal(0, 0.02), 0.02)
        est.add_odometry(t, *odom)
        if k % GNSS_EVERY == 0 and not outage[0] <= t < outage[1]:
            fx, fy = true[0] + rng.normal(0, GNSS_SIGMA), true[1] + rng.normal(0, GNSS_SIGMA)
            if jump[0] <= t < jump[1]:
                fx += 30.0
            fix = (fx, fy)
            in_flight.append((t + delays.uniform(0.0, max_delay), t, fx, fy))
        for _arrival, stamp, fx, fy in sorted(f for f in in_flight if f[0] <= t + 1e-9):
            est.add_gnss(stamp, fx, fy, GNSS_SIGMA, GNSS_SIGMA)
        in_flight = [f for f in in_flight if f[0] > t + 1e-9]
        pose = est.pose()
        if pose is not None:
            log.append((t, *true[:2], pose[0], pose[1], *dead[:2], *fix))
    return np.array(log), est


@pytest.fixture(scope="module")
def run():
    return simulate()


def _err(log, a, b):
    return np.hypot(log[:, a] - log[:, 1], log[:, b] - log[:, 2])


def test_beats_odometry_alone_and_gnss_alone(run):
    log, _ = run
    w = log[(log[:, 0] >= 5.0) & (log[:, 0] < OUTAGE[0])]
    fused = np.sqrt(np.mean(_err(w, 3, 4) ** 2))
    assert fused < 0.5 * np.sqrt(np.mean(_err(w, 7, 8) ** 2))
    assert fused < np.sqrt(np.mean(_err(w, 5, 6) ** 2))
    assert fused < 0.5


def test_outage_bridged_within_one_metre(run):
    log, _ = run
    w = log[(log[:, 0] >= OUTAGE[0]) & (log[:, 0] < OUTAGE[1] + 5.0)]
    assert _err(w, 3, 4).max() < 1.0


def test_jump_rejected_by_the_robust_model(run):
    log, est = run
    w = log[(log[:, 0] >= JUMP[0]) & (log[:, 0] < JUMP[1] + 3.0)]
    assert _err(w, 3, 4).max() < 1.0
    assert est.gnss_rejected >= 5
    cov = est.covariance()
    assert cov.shape == (3, 3) and 0.0 < cov[0, 0] < 1.0


def test_without_robust_model_the_jump_pulls():
    log, _ = simulate(duration=JUMP[1] + 1.0, outage=(0.0, 0.0), robust="none")
    w = log[(log[:, 0] >= JUMP[0]) & (log[:, 0] < JUMP[1] + 1.0)]
    assert _err(w, 3, 4).max() > 3.0


def test_late_fixes_are_as_good_as_fixes_on_time(run):
    # A GNSS driver up to 1 s behind the odometry (fixes out of order among themselves too):
    # each goes on the keyframe of its time. A keyframe stamped back in time would break
    # iSAM2's marginalisation for good (it did, with fixes 0.3 s late).
    log, est = simulate(duration=OUTAGE[0], max_delay=1.0)
    on_time = run[0][run[0][:, 0] < OUTAGE[0]]
    w, w0 = log[log[:, 0] >= 5.0], on_time[on_time[:, 0] >= 5.0]
    fused = np.sqrt(np.mean(_err(w, 3, 4) ** 2))
    assert est.solver_failures == 0, est.last_failure
    assert fused < 1.1 * np.sqrt(np.mean(_err(w0, 3, 4) ** 2))
    # Dropped: only fixes stamped before the one that arrived first and anchored the graph.
    assert est.gnss_used > 250 and est.gnss_dropped <= 4


def _straight_east(est, until):
    for k in range(0, round(until * 10) + 1):  # 1 m/s along x, odometry at 10 Hz
        est.add_odometry(k * 0.1, k * 0.1, 0.0, 0.0)


def test_a_late_fix_is_moved_by_the_odometry_since_its_stamp():
    # Accurate fixes 0.3 m to the side of the odometry, the start known to 1 m: a fix taken
    # as the robot's position at another time pulls it along x (to 4.81 m and 4.97 m).
    est = FactorGraphEstimator(lag=2.0, keyframe_period=0.2)
    est.add_gnss(0.0, 0.0, 0.0, 1.0, 1.0)
    _straight_east(est, 5.0)  # keyframes at 4.4, 4.6, 4.8 s; odometry to 5.0 s
    est.add_gnss(4.81, 4.81, 0.3, 0.05, 0.05)  # after the last keyframe: a new one at 5.0 s
    x, y, _ = est.pose()
    assert x == pytest.approx(5.0, abs=0.01) and y == pytest.approx(0.3, abs=0.01)
    est.add_gnss(4.5, 4.5, 0.3, 0.05, 0.05)  # between the keyframes of 4.4 and 4.6 s
    x, y, _ = est.pose()
    assert x == pytest.approx(5.0, abs=0.01) and y == pytest.approx(0.3, abs=0.02)
    assert est.gnss_used == 2 and est.gnss_dropped == 0 and est.solver_failures == 0


def test_a_fix_older_than_the_window_is_dropped():
    est = FactorGraphEstimator(lag=2.0, keyframe_period=0.2)
    est.add_gnss(0.0, 0.0, 0.0, 0.5, 0.5)
    _straight_east(est, 5.0)
    before = est.pose()
    est.add_gnss(1.0, 40.0, 40.0, 0.5, 0.5)  # 4 s old: its keyframe is marginalised
    assert est.gnss_dropped == 1 and est.solver_failures == 0
    assert est.pose() == pytest.approx(before)
    with pytest.raises(ValueError, match="keyframe periods"):
        FactorGraphEstimator(lag=0.3, keyframe_period=0.2)


class _FailingOnce:
    """A smoother whose next update raises as GTSAM's marginalisation did in the matrix."""

    def __init__(self, smoother):
        self._smoother, self.failed = smoother, False

    def __getattr__(self, name):
        return getattr(self._smoother, name)

    def update(self, *args):
        if not self.failed:
            self.failed = True
            raise IndexError("BayesTreeMarginalizationHelper: key 'x7' has no clique")
        return self._smoother.update(*args)


def test_a_failing_update_anchors_the_graph_again_at_the_last_estimate():
    est = FactorGraphEstimator(lag=2.0, keyframe_period=0.2)
    est.add_gnss(0.0, 0.0, 0.0, 0.5, 0.5)
    _straight_east(est, 1.0)
    variances = np.diag(est.covariance())
    est._smoother = _FailingOnce(est._smoother)
    for k in range(11, 14):  # the next keyframe fails
        est.add_odometry(k * 0.1, k * 0.1, 0.0, 0.0)
    assert est.solver_failures == 1 and "no clique" in est.last_failure
    assert est.pose() == pytest.approx((1.3, 0.0, 0.0), abs=1e-6)
    # Anchored again, no keyframe since: its variances doubled, capped (yaw's at π²).
    assert est._k == 0
    assert np.diag(est.covariance()) == pytest.approx(
        np.minimum(2.0 * variances, (1e4, 1e4, math.pi**2)))
    for k in range(14, 41):  # it goes on: odometry and fixes are used again
        est.add_odometry(k * 0.1, k * 0.1, 0.0, 0.0)
        if k % 5 == 0:
            est.add_gnss(k * 0.1, k * 0.1, 0.0, 0.5, 0.5)
    assert est.solver_failures == 1 and est.gnss_used == 6
    assert est.pose() == pytest.approx((4.0, 0.0, 0.0), abs=1e-3)
