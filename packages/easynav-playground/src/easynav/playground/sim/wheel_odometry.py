"""WheelOdometry: dead reckoning from wheel encoders, with the errors real encoders have."""

from __future__ import annotations

import math

import numpy as np


class WheelOdometry:
    """Integrates the robot's true motion increments into a drifting odometry pose.

    The pose starts at ``(0, 0, 0)`` in the ``odom`` frame (where the robot was switched on).
    Each increment ``(ds, dyaw)`` of true travel is measured as::

        ds'   = ds   * linear_scale  + N(0, linear_noise^2 * |ds|)
        dyaw' = dyaw * angular_scale + N(0, angular_noise^2 * |dyaw| + drift_per_metre^2 * |ds|)

    The scales are systematic errors (wheel radius, track width); the random terms make the
    error a random walk whose variance grows with distance, as with wheel slip. Noise
    coefficients are standard deviations per square-root metre (or radian).

    Thread contract: not thread-safe; the simulation loop owns it.

    Raises:
        ValueError: a scale that is not finite and > 0, or a negative noise coefficient.
    """

    def __init__(
        self,
        linear_scale: float = 1.01,
        angular_scale: float = 0.99,
        linear_noise: float = 0.01,
        angular_noise: float = 0.02,
        drift_per_metre: float = 0.01,
        rng: np.random.Generator | None = None,
    ) -> None:
        for name, value in (("linear_scale", linear_scale), ("angular_scale", angular_scale)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"WheelOdometry: {name} must be finite and > 0, got {value}")
        for name, value in (
            ("linear_noise", linear_noise),
            ("angular_noise", angular_noise),
            ("drift_per_metre", drift_per_metre),
        ):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"WheelOdometry: {name} must be finite and >= 0, got {value}")
        self.linear_scale = float(linear_scale)
        self.angular_scale = float(angular_scale)
        self.linear_noise = float(linear_noise)
        self.angular_noise = float(angular_noise)
        self.drift_per_metre = float(drift_per_metre)
        self._rng = rng if rng is not None else np.random.default_rng()
        self.x = 0.0
        self.y = 0.0
        self.yaw = 0.0
        self.v = 0.0
        self.w = 0.0

    def update(self, ds: float, dyaw: float, dt: float) -> None:
        """Add a true increment: ``ds`` metres along the heading and ``dyaw`` radians, in ``dt`` s.

        The measured twist ``(v, w)`` is the measured increment over ``dt``.
        """
        rng = self._rng
        ds_m = ds * self.linear_scale
        dyaw_m = dyaw * self.angular_scale
        if self.linear_noise > 0.0 and ds != 0.0:
            ds_m += rng.normal(0.0, self.linear_noise * math.sqrt(abs(ds)))
        yaw_var = self.angular_noise**2 * abs(dyaw) + self.drift_per_metre**2 * abs(ds)
        if yaw_var > 0.0:
            dyaw_m += rng.normal(0.0, math.sqrt(yaw_var))
        # Midpoint heading: second-order accurate for the arcs of one simulation step.
        mid = self.yaw + 0.5 * dyaw_m
        self.x += ds_m * math.cos(mid)
        self.y += ds_m * math.sin(mid)
        self.yaw = (self.yaw + dyaw_m + math.pi) % (2.0 * math.pi) - math.pi
        if dt > 0.0:
            self.v = ds_m / dt
            self.w = dyaw_m / dt
