"""ImuSensor: a simulated IMU (gyro with bias, accelerometer with gravity, absolute heading)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ImuReading:
    """One IMU sample in the robot frame (x forward, z up), as sensor_msgs/Imu carries it.

    ``yaw`` is the heading the IMU reports (an AHRS fusing a magnetometer: absolute, noisy);
    ``angular_velocity`` and ``linear_acceleration`` are 3-vectors (rad/s, m/s², gravity
    included: a robot at rest reads +g on z). ``*_std`` are the standard deviations the sensor
    declares (they go into the message covariances).
    """

    stamp: float
    yaw: float
    angular_velocity: tuple[float, float, float]
    linear_acceleration: tuple[float, float, float]
    yaw_std: float
    gyro_std: float
    accel_std: float


class ImuSensor:
    """A planar robot's IMU, sampled at ``rate`` Hz from the true motion.

    - Gyro z: true yaw rate + ``gyro_bias`` (constant, rad/s) + N(0, ``gyro_noise``²).
    - Accelerometer: true body acceleration (tangential ``dv/dt``, centripetal ``v·ω``) plus
      ``gravity`` on z, + N(0, ``accel_noise``²) per axis.
    - Heading: true yaw + N(0, ``yaw_noise``²) (0 disables the heading: covariance -1).

    Thread contract: not thread-safe; the simulation loop owns it.

    Raises:
        ValueError: a rate not finite and > 0, or a negative/non-finite noise or gravity.
    """

    def __init__(self, rate: float = 50.0, gyro_noise: float = 0.005, gyro_bias: float = 0.002,
                 accel_noise: float = 0.05, yaw_noise: float = 0.02, gravity: float = 9.80665,
                 rng: np.random.Generator | None = None) -> None:
        if not (math.isfinite(rate) and rate > 0.0):
            raise ValueError(f"ImuSensor: rate must be finite and > 0, got {rate}")
        for name, value in (("gyro_noise", gyro_noise), ("accel_noise", accel_noise),
                            ("yaw_noise", yaw_noise), ("gravity", gravity)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"ImuSensor: {name} must be finite and >= 0, got {value}")
        if not math.isfinite(gyro_bias):
            raise ValueError(f"ImuSensor: gyro_bias must be finite, got {gyro_bias}")
        self.rate = float(rate)
        self.period = 1.0 / self.rate
        self.gyro_noise, self.gyro_bias = float(gyro_noise), float(gyro_bias)
        self.accel_noise, self.yaw_noise, self.gravity = (float(accel_noise), float(yaw_noise),
                                                          float(gravity))
        self._rng = rng if rng is not None else np.random.default_rng()
        self._last_v: float | None = None
        self._last_stamp: float | None = None

    def sample(self, stamp: float, yaw: float, v: float, w: float) -> ImuReading:
        """A reading at ``stamp`` of a robot at heading ``yaw`` moving at ``(v, w)``."""
        rng = self._rng
        dv = 0.0
        if self._last_v is not None and self._last_stamp is not None and stamp > self._last_stamp:
            dv = (v - self._last_v) / (stamp - self._last_stamp)
        self._last_v, self._last_stamp = v, stamp
        noise = rng.normal(0.0, 1.0, 5)
        measured_yaw = yaw + self.yaw_noise * noise[0]
        measured_yaw = (measured_yaw + math.pi) % (2.0 * math.pi) - math.pi
        return ImuReading(
            stamp=stamp,
            yaw=measured_yaw,
            angular_velocity=(0.0, 0.0, w + self.gyro_bias + self.gyro_noise * noise[1]),
            linear_acceleration=(dv + self.accel_noise * noise[2],
                                 v * w + self.accel_noise * noise[3],
                                 self.gravity + self.accel_noise * noise[4]),
            yaw_std=self.yaw_noise,
            gyro_std=max(self.gyro_noise, abs(self.gyro_bias)),
            accel_std=self.accel_noise,
        )
