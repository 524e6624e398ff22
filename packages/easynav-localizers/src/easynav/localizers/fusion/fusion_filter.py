"""FusionFilter: one robot_localization filter (global or local) fed with EasyNav values."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from easynav.core.sensors import GNSSPerception, ImuPerception
from easynav.core.sensors.gnss_perception import COVARIANCE_TYPE_DIAGONAL_KNOWN
from easynav.core.types import Odometry
from easynav.localizers.fusion.fusion_input import FusionInput
from easynav.localizers.fusion.ukf_filter import (
    ROLL,
    VX,
    VY,
    VYAW,
    YAW,
    UkfFilter,
    Z,
    rotation_rpy,
)
from easynav.localizers.fusion.utm_projection import UtmProjection

#: Variance of a GNSS position whose covariance the receiver does not give (the original's).
UNKNOWN_GNSS_VARIANCE = 1.0


def quaternion_to_rpy(qx: float, qy: float, qz: float, qw: float) -> tuple[float, float, float]:
    """Fixed-axis roll, pitch, yaw of a unit quaternion ``(x, y, z, w)``."""
    roll = math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (qw * qy - qz * qx))))
    yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return roll, pitch, yaw


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class FusionFilter:
    """A :class:`UkfFilter` plus robot_localization's input handling.

    Every measurement (:meth:`add_odometry`, :meth:`add_imu`, :meth:`add_gnss`, ...) first
    predicts the filter to its stamp (a measurement older than the last one is fused without
    prediction; a GNSS fix older than the estimate is first moved on by the estimated motion
    since its stamp), then fuses the variables its input's ``_config`` selects, each part behind
    its Mahalanobis gate. A GNSS fix (status ≥ FIX) becomes a position in the local frame:
    UTM of the fix minus UTM of the geodetic origin (origin's zone), plus :attr:`gnss_offset`
    (moved by :meth:`reset_pose`). With GNSS inputs the filter is uninitialised until the first
    fix, which sets x and y (and yaw from the last IMU orientation, if any); without them, the
    first measurement initialises it.

    Counters ``accepted``/``rejected`` per input name are kept for diagnostics and tests.

    Exceptions: ValueError for a non-finite measurement (dropped by the caller with a warning).
    Thread contract: none; the plugin serialises all calls with one lock.
    """

    def __init__(
        self,
        ukf: UkfFilter,
        inputs: Sequence[FusionInput],
        projection: UtmProjection | None = None,
    ) -> None:
        self.ukf = ukf
        self.inputs = {i.name: i for i in inputs}
        self.projection = projection
        self.has_gnss = any(i.kind == "gps" for i in inputs)
        self.initialized = not self.has_gnss
        self.time: float | None = None
        self.gnss_offset = np.zeros(2)
        self.accepted: dict[str, int] = {name: 0 for name in self.inputs}
        self.rejected: dict[str, int] = {name: 0 for name in self.inputs}
        self._last_imu_rpy: tuple[float, float, float] | None = None
        self._previous_pose: dict[str, tuple[float, np.ndarray]] = {}
        self._first_pose: dict[str, np.ndarray] = {}

    # -- time ----------------------------------------------------------------------------------
    def predict_to(self, stamp: float) -> None:
        """Move the estimate forward to ``stamp`` (no-op for an earlier stamp)."""
        if self.time is None:
            self.time = stamp
            return
        if stamp > self.time:
            self.ukf.predict(stamp - self.time)
            self.time = stamp

    # -- measurements --------------------------------------------------------------------------
    def add_odometry(self, name: str, odometry: Odometry) -> None:
        """An ``odomN`` (pose and twist) or ``poseN`` (pose only) or ``twistN`` message."""
        source = self.inputs[name]
        stamp = odometry.header.stamp
        p = odometry.pose
        pose = np.array((p.x, p.y, p.z, *quaternion_to_rpy(p.qx, p.qy, p.qz, p.qw)))
        twist = np.array(odometry.twist.as_tuple())
        if not (np.all(np.isfinite(pose)) and np.all(np.isfinite(twist))):
            raise ValueError(f"{name}: non-finite odometry")
        self._begin(stamp)
        if source.kind in ("odom", "pose"):
            self._fuse_pose(source, stamp, pose, np.asarray(odometry.pose_covariance, float))
        if source.kind in ("odom", "twist"):
            idx = source.enabled(VX, VYAW)
            if idx:
                cov = np.asarray(odometry.twist_covariance, dtype=float).reshape(6, 6)
                sel = [i - VX for i in idx]
                self._correct(source, idx, twist[sel], cov[np.ix_(sel, sel)],
                              source.twist_threshold)

    def add_imu(self, name: str, imu: ImuPerception, gravity: float = 9.80665) -> None:
        """An ``imuN`` reading: orientation, angular velocity, linear acceleration."""
        source = self.inputs[name]
        q = np.asarray(imu.orientation, dtype=float)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(imu.angular_velocity))):
            raise ValueError(f"{name}: non-finite IMU reading")
        rpy = np.array(quaternion_to_rpy(*q)) if imu.has_orientation else None
        if rpy is not None:
            self._last_imu_rpy = tuple(rpy)
        self._begin(imu.stamp)
        if not self.initialized:
            return
        idx = source.enabled(ROLL, YAW)
        if idx and rpy is not None:
            sel = [i - ROLL for i in idx]
            cov = np.asarray(imu.orientation_covariance, dtype=float)
            self._correct(source, idx, rpy[sel], cov[np.ix_(sel, sel)], source.pose_threshold)
        idx = source.enabled(9, 11)
        if idx and imu.has_angular_velocity:
            sel = [i - 9 for i in idx]
            cov = np.asarray(imu.angular_velocity_covariance, dtype=float)
            values = np.asarray(imu.angular_velocity, dtype=float)[sel]
            self._correct(source, idx, values, cov[np.ix_(sel, sel)], source.twist_threshold)
        idx = source.enabled(12, 14)
        if idx and imu.has_linear_acceleration:
            acc = np.asarray(imu.linear_acceleration, dtype=float)
            if source.remove_gravitational_acceleration:
                r = rotation_rpy(*(rpy if rpy is not None else self.ukf.state[ROLL:YAW + 1]))
                acc = acc - r.T @ np.array((0.0, 0.0, gravity))
            sel = [i - 12 for i in idx]
            cov = np.asarray(imu.linear_acceleration_covariance, dtype=float)
            self._correct(source, idx, acc[sel], cov[np.ix_(sel, sel)],
                          source.acceleration_threshold)

    def add_gnss(self, name: str, fix: GNSSPerception) -> bool:
        """A ``gpsN`` fix; False when skipped (no fix) or rejected by the gate."""
        source = self.inputs[name]
        if not fix.has_fix or self.projection is None:
            return False
        east, north = self.projection.forward(fix.latitude, fix.longitude)
        position = np.array((east, north, fix.altitude - self.projection.altitude))
        position[:2] += self.gnss_offset
        if fix.position_covariance_type >= COVARIANCE_TYPE_DIAGONAL_KNOWN:
            cov = np.asarray(fix.position_covariance, dtype=float).reshape(3, 3)
        else:
            cov = np.eye(3) * UNKNOWN_GNSS_VARIANCE
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(cov))):
            raise ValueError(f"{name}: non-finite fix")
        if self.initialized and self.time is not None and fix.stamp < self.time:
            # A fix older than the estimate (it came through the sensors node while odometry
            # and IMU were already fused past it): where it was then, moved on by the motion
            # since. Fused as it is, it pulled the estimate back by the distance driven in the
            # lag (0.4 m in a burst of late fixes at 0.7 m/s on a loaded machine).
            position[:2] += self._displacement_since(fix.stamp)
        self._begin(fix.stamp)
        idx = source.enabled(0, Z)
        if not idx:
            return False
        if not self.initialized:
            values, variances = list(position[idx]), list(np.diag(cov)[idx])
            if self._last_imu_rpy is not None:
                idx, values, variances = idx + [YAW], values + [self._last_imu_rpy[2]], \
                    variances + [0.01]
            self.ukf.set_variables(idx, values, variances)
            self.initialized = True
            self.accepted[name] += 1
            return True
        return self._correct(source, idx, position[idx], cov[np.ix_(idx, idx)],
                             source.pose_threshold)

    def reset_pose(self, x: float, y: float, yaw: float, covariance: np.ndarray) -> None:
        """Continue from pose ``(x, y, yaw)`` (6×6 covariance): GNSS positions are shifted so
        the current estimate lands there (the original moved its UTM origin)."""
        state = self.ukf.state
        if self.initialized:
            self.gnss_offset += np.array((x - state[0], y - state[1]))
        cov = np.asarray(covariance, dtype=float).reshape(6, 6)
        self.ukf.set_variables([0, 1, YAW], [x, y, yaw],
                               [max(cov[0, 0], 1e-6), max(cov[1, 1], 1e-6), max(cov[5, 5], 1e-6)])
        self.initialized = True
        self._previous_pose.clear()

    # -- internals -----------------------------------------------------------------------------
    def _displacement_since(self, stamp: float) -> np.ndarray:
        """Map-frame (x, y) moved from ``stamp`` to the estimate's time at the estimated
        velocity (constant over the lag)."""
        state = self.ukf.state
        lag = self.time - stamp
        c, s = math.cos(state[YAW]), math.sin(state[YAW])
        vx, vy = state[VX], state[VY]
        return np.array((c * vx - s * vy, s * vx + c * vy)) * lag

    def _begin(self, stamp: float) -> None:
        self.predict_to(stamp)

    def _fuse_pose(self, source: FusionInput, stamp: float, pose: np.ndarray,
                   covariance: np.ndarray) -> None:
        idx = source.enabled(0, YAW)
        if not idx:
            return
        cov = covariance.reshape(6, 6)
        if source.relative:
            first = self._first_pose.setdefault(source.name, pose.copy())
            pose = self._relative(first, pose)
        if source.differential:
            previous = self._previous_pose.get(source.name)
            self._previous_pose[source.name] = (stamp, pose)
            if previous is None or stamp <= previous[0]:
                return
            dt = stamp - previous[0]
            delta = self._relative(previous[1], pose) / dt  # body-frame rates
            vidx = [i + VX for i in idx]
            sel = list(idx)
            # Variance of a difference of two poses, per second.
            self._correct(source, vidx, delta[sel], 2.0 * cov[np.ix_(sel, sel)] / (dt * dt),
                          source.twist_threshold)
            return
        if not self.initialized:
            return
        self._correct(source, idx, pose[idx], cov[np.ix_(idx, idx)], source.pose_threshold)

    @staticmethod
    def _relative(reference: np.ndarray, pose: np.ndarray) -> np.ndarray:
        # Pose in the frame of ``reference``: translation rotated back, angles subtracted.
        r = rotation_rpy(*reference[3:6])
        out = np.empty(6)
        out[:3] = r.T @ (pose[:3] - reference[:3])
        out[3:6] = [_wrap(a - b) for a, b in zip(pose[3:6], reference[3:6], strict=False)]
        return out

    def _correct(self, source: FusionInput, idx: list[int], values: np.ndarray,
                 cov: np.ndarray, threshold: float) -> bool:
        if not self.initialized:
            return False
        ok = self.ukf.correct(idx, values, cov, threshold)
        (self.accepted if ok else self.rejected)[source.name] += 1
        return ok
