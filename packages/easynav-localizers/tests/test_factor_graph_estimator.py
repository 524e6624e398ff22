"""FactorGraphEstimator (GTSAM fixed-lag smoothing) without ROS: tracking with GNSS noise, a
GNSS outage, GNSS jumps."""

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


def simulate(duration=150.0, outage=OUTAGE, jump=JUMP, robust="cauchy", seed=0):
    rng = np.random.default_rng(seed)
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
            est.add_gnss(t, fx, fy, GNSS_SIGMA, GNSS_SIGMA)
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
