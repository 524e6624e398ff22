"""FusionFilter: one robot_localization filter (global or local) fed with EasyNav values."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from easynav.common.sensors import GNSSPerception, ImuPerception
from easynav.common.sensors.gnss_perception import COVARIANCE_TYPE_DIAGONAL_KNOWN
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
#: A measurement older than the estimate by more than this (s) is fused as it is, not moved on
#: by the estimated motion: a stamp that old is more likely on another clock (0, wall time)
#: than late, and velocity × lag would throw the estimate anywhere.
MAX_LAG = 1.0


def quaternion_to_rpy(qx: float, qy: float, qz: float, qw: float) -> tuple[float, float, float]:
    """Fixed-axis roll, pitch, yaw of a unit quaternion ``(x, y, z, w)``."""
    roll = math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (qw * qy - qz * qx))))
    yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return roll, pitch, yaw


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def rpy_of_rotation(rotation: np.ndarray) -> np.ndarray:
    """Fixed-axis roll, pitch, yaw of a rotation matrix (inverse of :func:`rotation_rpy`)."""
    pitch = math.asin(max(-1.0, min(1.0, -rotation[2, 0])))
    return np.array((math.atan2(rotation[2, 1], rotation[2, 2]), pitch,
                     math.atan2(rotation[1, 0], rotation[0, 0])))


def pose_in(reference: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Pose ``(x, y, z, roll, pitch, yaw)`` expressed in the frame of pose ``reference``
    (robot_localization's ``reference.inverseTimes(pose)``)."""
    r = rotation_rpy(*reference[3:6])
    out = np.empty(6)
    out[:3] = r.T @ (pose[:3] - reference[:3])
    out[3:6] = rpy_of_rotation(r.T @ rotation_rpy(*pose[3:6]))
    return out


def robot_pose_from_child(pose: np.ndarray, covariance: np.ndarray,
                          robot_in_child: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The robot's pose and pose covariance from the pose of a frame mounted on it
    (``odomN_pose_use_child_frame``, robot_localization's ``pose * source_frame_trans``):
    ``pose`` (x, y, z, roll, pitch, yaw) is the child frame's, ``robot_in_child`` the robot
    frame's pose in the child frame (TF ``child → robot``); the 6×6 ``covariance`` is rotated
    by that transform's rotation (both blocks), as the original does."""
    r_child = rotation_rpy(*pose[3:6])
    r_mount = rotation_rpy(*robot_in_child[3:6])
    out = np.empty(6)
    out[:3] = pose[:3] + r_child @ robot_in_child[:3]
    out[3:6] = rpy_of_rotation(r_child @ r_mount)
    rot6 = np.zeros((6, 6))
    rot6[:3, :3] = r_mount
    rot6[3:, 3:] = r_mount
    return out, rot6.T @ np.asarray(covariance, dtype=float).reshape(6, 6) @ rot6


def attitude_in(reference: np.ndarray, rpy: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw ``rpy`` relative to the attitude ``reference``."""
    return rpy_of_rotation(rotation_rpy(*reference).T @ rotation_rpy(*rpy))


class FusionFilter:
    """A :class:`UkfFilter` plus robot_localization's input handling.

    Every measurement (:meth:`add_odometry`, :meth:`add_imu`, :meth:`add_gnss`, ...) first
    predicts the filter to its stamp (a measurement older than the last one is fused without
    prediction, its absolute parts — x, y, yaw of a pose, an IMU attitude, a GNSS fix — first
    moved on by the estimated motion since its stamp, up to :data:`MAX_LAG`), then fuses the
    variables its input's ``_config`` selects, each part behind its Mahalanobis gate. A GNSS
    fix (status ≥ FIX) becomes a position in the local frame: UTM of the fix minus UTM of the
    geodetic origin (origin's zone), plus :attr:`gnss_offset` (moved by :meth:`reset_pose`).
    With GNSS inputs the filter is uninitialised until the first fix, which sets x and y (and
    yaw from the last IMU orientation, if any); without them, the first measurement
    initialises it.

    ``_relative`` inputs are taken relative to their first message (a pose in the frame of the
    first pose; a fix minus the first fix, so the first fix is the origin). ``_differential``
    inputs fuse the change between two consecutive messages divided by the time between them
    as a robot-frame velocity (x, y, z → vx, vy, vz; roll, pitch, yaw → their rates), with the
    variance of a difference, ``(C_prev + C)/dt²``, behind the input's pose gate: a pose's
    change in the frame of the previous pose; an IMU's attitude change likewise; a fix's
    change (a map-frame displacement) rotated into the robot frame by the estimated attitude.
    A differential GNSS still initialises x and y from its first fix (as the original does).

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
        self._previous_pose: dict[str, tuple[float, np.ndarray, np.ndarray]] = {}
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
    def add_odometry(self, name: str, odometry: Odometry,
                     robot_in_child: np.ndarray | None = None) -> None:
        """An ``odomN`` (pose and twist) or ``poseN`` (pose only) or ``twistN`` message.

        ``robot_in_child``: for an ``odomN`` with ``_pose_use_child_frame``, the robot frame's
        pose (x, y, z, roll, pitch, yaw) in the message's child frame (TF ``child → robot``):
        the pose is the child frame's and becomes the robot's before it is fused (None: the
        pose is the robot's, as when the child frame is the robot frame or TF lacks it).
        """
        source = self.inputs[name]
        stamp = odometry.header.stamp
        p = odometry.pose
        pose = np.array((p.x, p.y, p.z, *quaternion_to_rpy(p.qx, p.qy, p.qz, p.qw)))
        twist = np.array(odometry.twist.as_tuple())
        if not (np.all(np.isfinite(pose)) and np.all(np.isfinite(twist))):
            raise ValueError(f"{name}: non-finite odometry")
        pose_cov = np.asarray(odometry.pose_covariance, float)
        if robot_in_child is not None and source.kind == "odom" and source.pose_use_child_frame:
            pose, pose_cov = robot_pose_from_child(pose, pose_cov,
                                                   np.asarray(robot_in_child, dtype=float))
        late = self._lag(stamp)
        self._begin(stamp)
        if source.kind in ("odom", "pose"):
            self._fuse_pose(source, stamp, pose, pose_cov, late)
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
        attitude = self._imu_attitude(source, imu.stamp, rpy,
                                      np.asarray(imu.orientation_covariance, dtype=float))
        late = self._lag(imu.stamp)
        self._begin(imu.stamp)
        if not self.initialized:
            return
        if attitude is not None:
            if not source.differential:
                attitude = (attitude[0], self._moved_on(attitude[0], attitude[1], late),
                            attitude[2])
            self._correct(source, *attitude, source.pose_threshold)
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
        """A ``gpsN`` fix; False when skipped (no fix, out of order, or the first of a
        differential input once initialised) or rejected by the gate."""
        source = self.inputs[name]
        if not fix.has_fix or self.projection is None:
            return False
        east, north = self.projection.forward(fix.latitude, fix.longitude)
        position = np.array((east, north, fix.altitude - self.projection.altitude))
        if fix.position_covariance_type >= COVARIANCE_TYPE_DIAGONAL_KNOWN:
            cov = np.asarray(fix.position_covariance, dtype=float).reshape(3, 3)
        else:
            cov = np.eye(3) * UNKNOWN_GNSS_VARIANCE
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(cov))):
            raise ValueError(f"{name}: non-finite fix")
        if source.differential:
            return self._add_gnss_step(source, fix.stamp, position, cov)
        if source.relative:  # the first fix is the origin
            position = position - self._first_pose.setdefault(name, position.copy())
        position[:2] += self.gnss_offset
        if self._lag(fix.stamp) > 0.0:
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
            return self._initialise_from_fix(name, idx, position, cov)
        return self._correct(source, idx, position[idx], cov[np.ix_(idx, idx)],
                             source.pose_threshold)

    def reset_pose(self, x: float, y: float, yaw: float, covariance: np.ndarray,
                   time: float | None = None,
                   twist: Sequence[float] | None = None) -> None:
        """Continue from pose ``(x, y, yaw)`` (6×6 covariance): GNSS positions are shifted so
        the current estimate lands there (the original moved its UTM origin). ``time``: the
        instant the pose describes; the filter's clock moves there (later measurements are
        predicted from it, earlier ones fused as late ones); None keeps the filter's clock.

        ``twist``: the robot's body velocity ``(vx, vy, vyaw)`` then. A filter that has not
        run yet starts from it, with variance 1 so that the first velocity measurement takes
        over: its initial covariance (robot_localization's 1e-9) would otherwise hold a
        standstill firmly, and the first steps after a handover while driving were lost (1 cm
        and 0.3° a step at 0.5 m/s, kept for good by dead reckoning). A running filter keeps
        its own velocity."""
        if time is not None and self.time is not None and time > self.time:
            self.predict_to(time)  # the estimate the pose replaces, at the pose's time
        state = self.ukf.state
        if self.initialized:
            then = state[:2] - self._displacement_since(time) if (
                time is not None and self.time is not None and time < self.time) else state[:2]
            self.gnss_offset += np.array((x - then[0], y - then[1]))
        cov = np.asarray(covariance, dtype=float).reshape(6, 6)
        self.ukf.set_variables([0, 1, YAW], [x, y, yaw],
                               [max(cov[0, 0], 1e-6), max(cov[1, 1], 1e-6), max(cov[5, 5], 1e-6)])
        fresh = self.time is None or not self.initialized  # nothing corrected yet
        if twist is not None and fresh and np.all(np.isfinite(twist)):
            self.ukf.set_variables([VX, VY, VYAW], [float(v) for v in twist], [1.0] * 3)
        self.initialized = True
        self._previous_pose.clear()
        if time is not None:
            self.time = time

    # -- internals -----------------------------------------------------------------------------
    def _initialise_from_fix(self, name: str, idx: list[int], position: np.ndarray,
                             cov: np.ndarray) -> bool:
        values, variances = list(position[idx]), list(np.diag(cov)[idx])
        if self._last_imu_rpy is not None:
            idx, values, variances = idx + [YAW], values + [self._last_imu_rpy[2]], \
                variances + [0.01]
        self.ukf.set_variables(idx, values, variances)
        self.initialized = True
        self.accepted[name] += 1
        return True

    def _add_gnss_step(self, source: FusionInput, stamp: float, position: np.ndarray,
                       cov: np.ndarray) -> bool:
        """A differential ``gpsN``: the displacement since the previous fix, over the time
        between them, rotated into the robot frame, fused as a velocity."""
        name = source.name
        previous = self._previous_pose.get(name)
        if previous is not None and stamp <= previous[0]:
            return False  # out of order
        self._previous_pose[name] = (stamp, position, cov)
        self._begin(stamp)
        idx = source.enabled(0, Z)
        if not idx:
            return False
        if not self.initialized:  # the first fix still places the robot (the original's)
            absolute = position.copy()
            absolute[:2] += self.gnss_offset
            return self._initialise_from_fix(name, idx, absolute, cov)
        if previous is None:
            return False
        dt = stamp - previous[0]
        turn = rotation_rpy(*self.ukf.state[ROLL:YAW + 1]).T  # map → robot frame
        velocity = turn @ (position - previous[1]) / dt
        velocity_cov = turn @ (cov + previous[2]) @ turn.T / (dt * dt)
        return self._correct(source, [i + VX for i in idx], velocity[idx],
                             velocity_cov[np.ix_(idx, idx)], source.pose_threshold)

    def _imu_attitude(self, source: FusionInput, stamp: float, rpy: np.ndarray | None,
                      cov: np.ndarray) -> tuple[list[int], np.ndarray, np.ndarray] | None:
        """The attitude part of an IMU reading as ``(state indices, values, covariance)``:
        the angles (relative to the first reading with ``_relative``) or, with
        ``_differential``, the change since the previous reading as body rates; None when
        there is nothing to fuse."""
        idx = source.enabled(ROLL, YAW)
        if not idx or rpy is None:
            return None
        sel = [i - ROLL for i in idx]
        if source.differential:
            previous = self._previous_pose.get(source.name)
            if previous is not None and stamp <= previous[0]:
                return None
            self._previous_pose[source.name] = (stamp, rpy, cov)
            if previous is None:
                return None
            dt = stamp - previous[0]
            rates = attitude_in(previous[1], rpy) / dt
            rates_cov = (cov + previous[2]) / (dt * dt)
            return ([i + VX for i in idx], rates[sel], rates_cov[np.ix_(sel, sel)])
        if source.relative:
            rpy = attitude_in(self._first_pose.setdefault(source.name, rpy.copy()), rpy)
        return (idx, rpy[sel], cov[np.ix_(sel, sel)])

    def _displacement_since(self, stamp: float) -> np.ndarray:
        """Map-frame (x, y) moved from ``stamp`` to the estimate's time at the estimated
        velocity (constant over the lag)."""
        state = self.ukf.state
        lag = self.time - stamp
        heading = state[YAW] - 0.5 * state[VYAW] * lag  # the heading halfway through the lag
        c, s = math.cos(heading), math.sin(heading)
        vx, vy = state[VX], state[VY]
        return np.array((c * vx - s * vy, s * vx + c * vy)) * lag

    def _lag(self, stamp: float) -> float:
        """How much older than the estimate a measurement stamped ``stamp`` is: 0 when it is
        not, or when it is older by more than :data:`MAX_LAG`."""
        if not self.initialized or self.time is None or stamp >= self.time:
            return 0.0
        lag = self.time - stamp
        return lag if lag <= MAX_LAG else 0.0

    def _moved_on(self, idx: Sequence[int], values: np.ndarray, lag: float) -> np.ndarray:
        """Absolute measurements of state variables ``idx`` taken ``lag`` seconds before the
        estimate's time, moved on by the estimated planar motion since: x and y by
        :meth:`_displacement_since`, yaw by the yaw rate. A late measurement is fused at the
        estimate's time, without prediction (as robot_localization fuses it without
        ``smooth_lagged_data``); as they were, a burst of IMU yaws 0.2-0.4 s old pulled the
        estimate 15° back in a turn on the spot at 1 rad/s."""
        if lag <= 0.0:
            return values
        out = np.array(values, dtype=float)
        moved = self._displacement_since(self.time - lag)
        for k, i in enumerate(idx):
            if i in (0, 1):
                out[k] += moved[i]
            elif i == YAW:
                out[k] = _wrap(out[k] + self.ukf.state[VYAW] * lag)
        return out

    def _begin(self, stamp: float) -> None:
        self.predict_to(stamp)

    def _fuse_pose(self, source: FusionInput, stamp: float, pose: np.ndarray,
                   covariance: np.ndarray, late: float = 0.0) -> None:
        idx = source.enabled(0, YAW)
        if not idx:
            return
        cov = np.asarray(covariance, dtype=float).reshape(6, 6)
        if source.differential:
            previous = self._previous_pose.get(source.name)
            if previous is not None and stamp <= previous[0]:
                return  # out of order: robot_localization drops it
            self._previous_pose[source.name] = (stamp, pose, cov)
            if previous is None:
                return
            dt = stamp - previous[0]
            rates = pose_in(previous[1], pose) / dt  # robot-frame velocities
            # Both covariances into the previous pose's frame (translation block).
            turn = np.eye(6)
            turn[:3, :3] = rotation_rpy(*previous[1][3:6]).T
            rates_cov = turn @ (cov + previous[2]) @ turn.T / (dt * dt)
            self._correct(source, [i + VX for i in idx], rates[idx],
                          rates_cov[np.ix_(idx, idx)], source.pose_threshold)
            return
        if source.relative:
            first = self._first_pose.setdefault(source.name, pose.copy())
            pose = pose_in(first, pose)
        if not self.initialized:
            return
        values = self._moved_on(idx, pose[idx], late)
        self._correct(source, idx, values, cov[np.ix_(idx, idx)], source.pose_threshold)

    def _correct(self, source: FusionInput, idx: list[int], values: np.ndarray,
                 cov: np.ndarray, threshold: float) -> bool:
        if not self.initialized:
            return False
        ok = self.ukf.correct(idx, values, cov, threshold)
        (self.accepted if ok else self.rejected)[source.name] += 1
        return ok
