"""UkfFilter: robot_localization's 15-state UKF, on filterpy's UnscentedKalmanFilter."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: State layout (robot_localization's): pose in the world frame, velocities and accelerations in
#: the robot frame.
X, Y, Z, ROLL, PITCH, YAW, VX, VY, VZ, VROLL, VPITCH, VYAW, AX, AY, AZ = range(15)
STATE_SIZE = 15
ANGLES = (ROLL, PITCH, YAW)
#: Variables held at zero in two_d_mode (robot_localization fuses zeros for them).
THREE_D_ONLY = (Z, ROLL, PITCH, VZ, VROLL, VPITCH, AZ)

#: robot_localization's default process noise (diagonal) and initial estimate covariance.
DEFAULT_PROCESS_NOISE = (
    0.05, 0.05, 0.06, 0.03, 0.03, 0.06, 0.025, 0.025, 0.04, 0.01, 0.01, 0.02, 0.01, 0.01, 0.015,
)
DEFAULT_INITIAL_COVARIANCE = (1e-9,) * STATE_SIZE
#: Variance kept on the variables two_d_mode pins (a zero would break the sigma points).
_PINNED_VARIANCE = 1e-9


def _wrap(a: np.ndarray | float) -> np.ndarray | float:
    return (np.asarray(a) + math.pi) % (2.0 * math.pi) - math.pi


def square_matrix(values: Sequence[float], name: str) -> np.ndarray:
    """A 15×15 matrix from 225 values (row major) or 15 diagonal values; ValueError naming
    ``name`` otherwise (robot_localization accepts both forms)."""
    arr = np.asarray(values, dtype=float)
    if arr.size == STATE_SIZE:
        matrix = np.diag(arr)
    elif arr.size == STATE_SIZE * STATE_SIZE:
        matrix = arr.reshape(STATE_SIZE, STATE_SIZE)
    else:
        raise ValueError(f"{name}: {arr.size} values, expected 15 (diagonal) or 225 (15×15)")
    if not np.all(np.isfinite(matrix)):
        raise ValueError(f"{name}: values must be finite")
    return matrix


def rotation_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Robot-to-world rotation of the fixed-axis roll, pitch, yaw (ZYX) angles."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    return np.array((
        (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
        (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
        (-sp, cp * sr, cp * cr),
    ))


def transition(state: np.ndarray, dt: float) -> np.ndarray:
    """robot_localization's omnidirectional constant-acceleration model over ``dt`` seconds.

    Position moves by the robot-frame velocity and acceleration rotated into the world frame;
    the angles by the body rates turned into Euler rates; velocities by the accelerations.
    """
    s = np.array(state, dtype=float)
    roll, pitch, yaw = s[ROLL], s[PITCH], s[YAW]
    rot = rotation_rpy(roll, pitch, yaw)
    s[X:Z + 1] += rot @ (s[VX:VZ + 1] * dt + 0.5 * s[AX:AZ + 1] * dt * dt)
    cr, sr = math.cos(roll), math.sin(roll)
    cp = math.cos(pitch)
    cp = cp if abs(cp) > 1e-9 else math.copysign(1e-9, cp)
    tp = math.sin(pitch) / cp
    wx, wy, wz = s[VROLL], s[VPITCH], s[VYAW]
    s[ROLL] += (wx + sr * tp * wy + cr * tp * wz) * dt
    s[PITCH] += (cr * wy - sr * wz) * dt
    s[YAW] += (sr / cp * wy + cr / cp * wz) * dt
    s[VX:VZ + 1] += s[AX:AZ + 1] * dt
    s[ROLL:YAW + 1] = _wrap(s[ROLL:YAW + 1])
    return s


def transition_batch(states: np.ndarray, dt: float) -> np.ndarray:
    """:func:`transition` of every row of ``states`` (N×15) at once (the UKF's sigma points);
    the tests hold it to the one-state reference."""
    s = np.array(states, dtype=float)
    roll, pitch, yaw = s[:, ROLL], s[:, PITCH], s[:, YAW]
    cr, sr, cp, sp, cy, sy = (np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch),
                              np.cos(yaw), np.sin(yaw))
    rot = np.empty((len(s), 3, 3))
    rot[:, 0] = np.stack((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr), axis=1)
    rot[:, 1] = np.stack((sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr), axis=1)
    rot[:, 2] = np.stack((-sp, cp * sr, cp * cr), axis=1)
    move = s[:, VX:VZ + 1] * dt + 0.5 * s[:, AX:AZ + 1] * dt * dt
    s[:, X:Z + 1] += np.einsum("nij,nj->ni", rot, move)
    cp = np.where(np.abs(cp) > 1e-9, cp, np.copysign(1e-9, cp))
    tp = sp / cp
    wx, wy, wz = s[:, VROLL].copy(), s[:, VPITCH].copy(), s[:, VYAW].copy()
    s[:, ROLL] += (wx + sr * tp * wy + cr * tp * wz) * dt
    s[:, PITCH] += (cr * wy - sr * wz) * dt
    s[:, YAW] += (sr / cp * wy + cr / cp * wz) * dt
    s[:, VX:VZ + 1] += s[:, AX:AZ + 1] * dt
    s[:, ROLL:YAW + 1] = _wrap(s[:, ROLL:YAW + 1])
    return s


def _circular_mean(sigmas: np.ndarray, weights: np.ndarray, angle_columns: Sequence[int]):
    mean = weights @ sigmas
    for c in angle_columns:
        mean[c] = math.atan2(weights @ np.sin(sigmas[:, c]), weights @ np.cos(sigmas[:, c]))
    return mean


class UkfFilter:
    """The 15-state unscented Kalman filter of robot_localization, on filterpy.

    State: ``x y z roll pitch yaw`` (world frame), ``vx vy vz vroll vpitch vyaw`` and ``ax ay
    az`` (robot frame). :meth:`predict` runs :func:`transition` through filterpy's UKF (Merwe
    sigma points with ``alpha``, ``beta``, ``kappa``; process noise scaled by ``dt`` as
    robot_localization does); :meth:`correct` fuses a measurement of any subset of the state
    (a linear selection), with angles compared on the circle, after a Mahalanobis gate: a
    measurement whose distance ``sqrt(yᵀ S⁻¹ y)`` is at or above ``threshold`` is rejected and
    leaves the filter unchanged. ``two_d_mode`` pins z, roll, pitch and their rates to zero.

    Raises ImportError naming the extra when filterpy is missing. Thread contract: none (the
    owner serialises every call).
    """

    def __init__(
        self,
        alpha: float = 0.001,
        beta: float = 2.0,
        kappa: float = 0.0,
        process_noise: np.ndarray | None = None,
        initial_covariance: np.ndarray | None = None,
        initial_state: Sequence[float] | None = None,
        two_d_mode: bool = False,
    ) -> None:
        try:
            from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter
        except ImportError as exc:  # an optional extra
            raise ImportError(
                "the fusion localizer needs filterpy: pip install easynav-localizers[fusion]"
            ) from exc
        # Sigma points are spread with a plain subtraction: an angle beyond ±π is wrapped by
        # the transition and by every residual.
        points = MerweScaledSigmaPoints(STATE_SIZE, alpha=alpha, beta=beta, kappa=kappa)
        self._ukf = UnscentedKalmanFilter(
            dim_x=STATE_SIZE, dim_z=1, dt=0.0, hx=None, fx=transition, points=points,
            x_mean_fn=self._mean_x, residual_x=self._residual_x,
        )
        # Vectorised replacements of filterpy's per-sigma-point loops (same arithmetic).
        self._ukf.compute_process_sigmas = self._compute_process_sigmas
        self._ukf.cross_variance = self._cross_variance
        self._angle_columns: list[int] = []
        self.process_noise = (
            np.diag(DEFAULT_PROCESS_NOISE) if process_noise is None else np.array(process_noise)
        )
        self.two_d_mode = two_d_mode
        self.reset(
            np.zeros(STATE_SIZE) if initial_state is None else np.asarray(initial_state, float),
            np.diag(DEFAULT_INITIAL_COVARIANCE) if initial_covariance is None
            else np.array(initial_covariance, dtype=float),
        )
        #: Squared Mahalanobis distance of the last :meth:`correct` (accepted or not).
        self.last_distance = math.nan

    # -- state ---------------------------------------------------------------------------------
    @property
    def state(self) -> np.ndarray:
        """The 15-vector estimate (a copy)."""
        return self._ukf.x.copy()

    @property
    def covariance(self) -> np.ndarray:
        """The 15×15 estimate covariance (a copy)."""
        return self._ukf.P.copy()

    def reset(self, state: np.ndarray, covariance: np.ndarray) -> None:
        """Set the estimate and its covariance."""
        self._ukf.x = np.array(state, dtype=float)
        self._ukf.P = np.array(covariance, dtype=float)
        self._constrain()

    def set_variables(self, indices: Sequence[int], values: Sequence[float],
                      variances: Sequence[float]) -> None:
        """Overwrite some state variables (and make them independent of the rest), e.g. the
        first GNSS fix sets x and y."""
        idx = list(indices)
        self._ukf.x[idx] = values
        self._ukf.P[idx, :] = 0.0
        self._ukf.P[:, idx] = 0.0
        self._ukf.P[idx, idx] = variances
        self._constrain()

    # -- filter steps --------------------------------------------------------------------------
    def predict(self, dt: float) -> None:
        """Move the estimate ``dt`` seconds ahead (nothing for ``dt <= 0``)."""
        if dt <= 0.0:
            return
        self._ukf.Q = self.process_noise * dt
        self._ukf.predict(
            dt=dt, UT=lambda sig, wm, wc, q, *_: self._transform(sig, wm, wc, q, ANGLES))
        self._constrain()

    def correct(
        self,
        indices: Sequence[int],
        values: Sequence[float],
        covariance: np.ndarray,
        threshold: float = math.inf,
    ) -> bool:
        """Fuse a measurement of state ``indices`` (``values``, ``covariance`` of those).

        Returns False (filter unchanged) when the squared Mahalanobis distance is at least
        ``threshold²``. Raises ValueError on a non-finite measurement.
        """
        idx = np.asarray(indices, dtype=int)
        z = np.asarray(values, dtype=float)
        r = np.asarray(covariance, dtype=float).reshape(len(idx), len(idx))
        if not (np.all(np.isfinite(z)) and np.all(np.isfinite(r))):
            raise ValueError("measurement or covariance not finite")
        # A zero variance would make S singular and the filter overconfident.
        r = r + np.diag(np.maximum(1e-9 - np.diag(r), 0.0))
        angle_columns = [k for k, i in enumerate(idx) if i in ANGLES]
        ukf = self._ukf
        # Sigma points of the current estimate: filterpy would reuse the predicted ones, stale
        # after an earlier correction in the same cycle.
        ukf.sigmas_f = ukf.points_fn.sigma_points(ukf.x, ukf.P)

        def residual_z(a, b):
            d = np.subtract(a, b)
            for k in angle_columns:
                d[..., k] = _wrap(d[..., k])
            return d

        ukf.residual_z = residual_z
        self._angle_columns = angle_columns
        saved = (ukf.x.copy(), ukf.P.copy())
        ukf.update(
            z, R=r, hx=lambda s: s[idx],
            UT=lambda sig, wm, wc, noise, *_: self._transform(sig, wm, wc, noise, angle_columns),
        )
        y, si = ukf.y, ukf.SI
        self.last_distance = float(y @ si @ y)
        if threshold < math.inf and self.last_distance >= threshold * threshold:
            ukf.x, ukf.P = saved
            return False
        self._constrain()
        return True

    # -- internals -----------------------------------------------------------------------------
    @staticmethod
    def _residual_x(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        d = np.subtract(a, b)
        d[..., ROLL:YAW + 1] = _wrap(d[..., ROLL:YAW + 1])
        return d

    def _compute_process_sigmas(self, dt, fx=None, **fx_args) -> None:
        ukf = self._ukf
        ukf.sigmas_f = transition_batch(ukf.points_fn.sigma_points(ukf.x, ukf.P), dt)

    def _cross_variance(self, x, z, sigmas_f, sigmas_h) -> np.ndarray:
        dx = sigmas_f - x
        dx[:, ROLL:YAW + 1] = _wrap(dx[:, ROLL:YAW + 1])
        dz = sigmas_h - z
        for k in self._angle_columns:
            dz[:, k] = _wrap(dz[:, k])
        return (dx * self._ukf.Wc[:, None]).T @ dz

    @staticmethod
    def _mean_x(sigmas: np.ndarray, weights: np.ndarray) -> np.ndarray:
        return _circular_mean(sigmas, weights, ANGLES)

    @staticmethod
    def _transform(sigmas, wm, wc, noise, angle_columns):
        mean = _circular_mean(sigmas, wm, angle_columns)
        d = sigmas - mean
        for k in angle_columns:
            d[:, k] = _wrap(d[:, k])
        cov = d.T @ (wc[:, None] * d)
        if noise is not None:
            cov = cov + noise
        return mean, cov

    def _constrain(self) -> None:
        ukf = self._ukf
        ukf.x[ROLL:YAW + 1] = _wrap(ukf.x[ROLL:YAW + 1])
        # Keep P symmetric (round-off of the sigma-point sums).
        ukf.P = 0.5 * (ukf.P + ukf.P.T)
        if self.two_d_mode:
            pinned = list(THREE_D_ONLY)
            ukf.x[pinned] = 0.0
            ukf.P[pinned, :] = 0.0
            ukf.P[:, pinned] = 0.0
            ukf.P[pinned, pinned] = _PINNED_VARIANCE
