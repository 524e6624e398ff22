"""GpsPoseEstimator: the GPS localizer's algorithm (UTM position, complementary-filtered yaw)."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import GNSSPerception, ImuPerception
from easynav.common.sensors.gnss_perception import COVARIANCE_TYPE_DIAGONAL_KNOWN
from easynav.localizers.fusion.fusion_filter import quaternion_to_rpy
from easynav.localizers.fusion.utm_projection import UtmProjection

#: The original's weights: 0.99 on the gyro-integrated yaw, 0.01 on the IMU's own yaw.
GYRO_WEIGHT = 0.99
#: Variance of a position whose fix has no covariance, and of an IMU yaw without one.
UNKNOWN_VARIANCE = 1.0
#: Rejected fixes in a row after which the next one is taken whatever its distance: an offset
#: that persists is real (the robot was carried, or the estimate was the wrong one).
GATE_RELEASE = 5
#: Standard deviations of a fix's own noise allowed beyond the way the robot can have driven.
GATE_SIGMAS = 5.0
#: A fix stamped this much (s) before the last fix taken means the clock went back (a
#: simulator or a bag restarted): the estimator starts its time line again. Less: out of order.
CLOCK_JUMP = 1.0


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class GpsPoseEstimator:
    """Position from GNSS, yaw from an IMU, as the original GpsLocalizer, with its gaps filled.

    - Position: UTM(fix) − UTM(first fix) (the first fix's zone, no altitude), plus
      ``(x0, y0)`` when an initial pose is given (the first fix lands there). Its covariance is
      the fix's (diagonal known or full), else :data:`UNKNOWN_VARIANCE` per axis.
    - Yaw: a complementary filter, ``yaw ← 0.99·(yaw + ω_z·dt) + 0.01·yaw_IMU``. The original
      integrated the raw gyro and never fed the filtered value back (so its yaw drifted with the
      gyro bias); here the filtered yaw is the integrator's state. Its variance follows the same
      recursion, ``σ² ← 0.99²·(σ² + σ_ω²·dt²) + 0.01²·σ²_IMU``. Roll and pitch are the IMU's.

    - Jump gate (not in the original): with ``gate_speed`` > 0, a fix farther from the
      estimate than ``gate_speed`` times the time since the last fix taken, plus
      :data:`GATE_SIGMAS` standard deviations of its own noise, is rejected (a receiver's
      multipath jump: one fix 30 m off moved ``robot_pose`` 30 m for a fix period), unless
      :data:`GATE_RELEASE` fixes in a row were (``released_jumps`` counts the far fixes taken
      so). ``rejected_fixes`` counts the rejected ones. An unstamped fix (0) is not gated (the
      time since the last one is unknown); one older than the last fix taken is dropped, unless
      by more than :data:`CLOCK_JUMP` (the clock went back: its time line starts again).
      ``fixes_taken`` counts the fixes taken and the resets (a change means a new anchor).

    Raises ImportError naming the extra without pyproj. Thread contract: none (the plugin
    serialises calls).
    """

    def __init__(self, x0: float = 0.0, y0: float = 0.0, yaw0: float = 0.0,
                 gate_speed: float = 0.0) -> None:
        self.gate_speed = float(gate_speed)
        self.rejected_fixes = 0
        self.released_jumps = 0
        self.fixes_taken = 0
        self._rejected_in_a_row = 0
        self.fix_stamp = 0.0
        #: Stamp of the last fix taken (0: unstamped), what its position is of.
        self.last_fix_stamp = 0.0
        self.offset = np.array((x0, y0))
        self.projection: UtmProjection | None = None
        self.position: np.ndarray | None = None
        self.position_covariance = np.eye(2) * UNKNOWN_VARIANCE
        self.yaw = yaw0
        self.yaw_variance = UNKNOWN_VARIANCE
        self.roll = 0.0
        self.pitch = 0.0
        self.angular_velocity = np.zeros(3)
        self._yaw_initialised = False
        self._imu_stamp: float | None = None
        self.stamp = 0.0

    def add_fix(self, fix: GNSSPerception) -> bool:
        """Take a fix; False when it has none (ignored) or the jump gate rejects it."""
        if not fix.has_fix:
            return False
        if 0.0 < fix.stamp < self.fix_stamp:
            if fix.stamp > self.fix_stamp - CLOCK_JUMP:
                return False  # out of order
            # The clock went back (a restart): a new time line, the first fix on it ungated.
            self.fix_stamp = self.stamp = self.last_fix_stamp = 0.0
            self._rejected_in_a_row = 0
            self._imu_stamp = None
            self.position = None
        if self.projection is None:
            self.projection = UtmProjection(fix.latitude, fix.longitude, fix.altitude)
        east, north = self.projection.forward(fix.latitude, fix.longitude)
        position = np.array((east, north)) + self.offset
        cov = np.asarray(fix.position_covariance, dtype=float).reshape(3, 3)
        if fix.position_covariance_type >= COVARIANCE_TYPE_DIAGONAL_KNOWN and np.all(
            np.isfinite(cov)
        ):
            covariance = cov[:2, :2].copy()
        else:
            covariance = np.eye(2) * UNKNOWN_VARIANCE
        if self._jumps(position, covariance, fix.stamp):
            if self._rejected_in_a_row < GATE_RELEASE:
                self.rejected_fixes += 1
                self._rejected_in_a_row += 1
                return False
            self.released_jumps += 1  # the offset lasted: taken
        self._rejected_in_a_row = 0
        self.fixes_taken += 1
        self.position, self.position_covariance = position, covariance
        self.last_fix_stamp = fix.stamp
        self.fix_stamp = max(self.fix_stamp, fix.stamp)
        self.stamp = max(self.stamp, fix.stamp)
        return True

    def _jumps(self, position: np.ndarray, covariance: np.ndarray, stamp: float) -> bool:
        """Whether a fix at ``position`` is farther than the gate allows."""
        if self.gate_speed <= 0.0 or self.position is None or stamp <= 0.0:
            return False
        elapsed = max(stamp - self.fix_stamp, 0.0)
        sigma = math.sqrt(max(float(np.max(np.diag(covariance))), 0.0))
        reach = self.gate_speed * elapsed + GATE_SIGMAS * sigma
        return float(np.hypot(*(position - self.position))) > reach

    def add_imu(self, imu: ImuPerception) -> None:
        """Take an IMU reading: roll and pitch, and one step of the yaw filter."""
        imu_yaw = None
        var_imu = UNKNOWN_VARIANCE
        if imu.has_orientation:
            self.roll, self.pitch, imu_yaw = quaternion_to_rpy(*imu.orientation)
            var_imu = float(imu.orientation_covariance[2, 2]) or UNKNOWN_VARIANCE
        if imu.has_angular_velocity:
            self.angular_velocity = np.asarray(imu.angular_velocity, dtype=float).copy()
        if not self._yaw_initialised:
            if imu_yaw is not None:
                self.yaw, self.yaw_variance = imu_yaw, var_imu
                self._yaw_initialised = True
            self._imu_stamp = imu.stamp
            return
        dt = 0.0 if self._imu_stamp is None else max(0.0, imu.stamp - self._imu_stamp)
        self._imu_stamp = imu.stamp
        wz = float(imu.angular_velocity[2]) if imu.has_angular_velocity else 0.0
        var_w = float(imu.angular_velocity_covariance[2, 2]) if imu.has_angular_velocity else 0.0
        predicted = self.yaw + wz * dt
        variance = self.yaw_variance + var_w * dt * dt
        if imu_yaw is None:
            self.yaw, self.yaw_variance = _wrap(predicted), variance
        else:
            g = GYRO_WEIGHT
            self.yaw = _wrap(predicted + (1.0 - g) * _wrap(imu_yaw - predicted))
            self.yaw_variance = g * g * variance + (1.0 - g) ** 2 * var_imu
        self.stamp = max(self.stamp, imu.stamp)

    @property
    def imu_stamp(self) -> float | None:
        """Stamp of the last IMU reading (the time :attr:`yaw` is of), None before one."""
        return self._imu_stamp

    def reset(self, x: float, y: float, yaw: float,
              current: tuple[float, float] | None = None, stamp: float = 0.0) -> None:
        """Move the estimate to ``(x, y, yaw)`` (the robot's pose at ``stamp``): later fixes
        are shifted to agree. ``current``: where the estimate puts the robot at that instant
        (the last fix moved on by odometry), when known; else the last fix's position (the
        motion since it would stay in the shift as a bias)."""
        self.stamp = max(self.stamp, stamp)
        self.last_fix_stamp = stamp  # what the position is now of (0: unknown)
        self._rejected_in_a_row = 0
        self.fixes_taken += 1
        if self.position is not None:
            base = self.position if current is None else np.asarray(current, dtype=float)
            self.offset += np.array((x, y)) - base
            self.position = np.array((x, y))
        else:
            self.offset = np.array((x, y))
        self.yaw = yaw
        self._yaw_initialised = True

    def covariance6(self) -> np.ndarray:
        """6×6 pose covariance (x, y, z, roll, pitch, yaw): z, roll, pitch unknown (1.0)."""
        cov = np.eye(6) * UNKNOWN_VARIANCE
        cov[:2, :2] = self.position_covariance
        cov[5, 5] = self.yaw_variance
        return cov
