"""LaserScanner: a 2D laser rangefinder ray-cast against the world and moving obstacles."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.ray_casting import cast_rays_discs, cast_rays_grid
from easynav.playground.sim.world import World


class LaserScanner:
    """A planar scanner with ``beams`` rays over ``fov`` radians, centred on its x axis.

    Ranges follow REP-117: ``+inf`` when nothing is within ``max_range``, ``-inf`` when the
    return is closer than ``min_range``; finite ranges carry Gaussian noise of
    ``range_noise_std`` (m). A scan is instantaneous (no motion distortion).

    Beam ``i`` points at ``angle_min + i * angle_increment`` in the scanner frame. With a full
    circle (``fov`` = 2π) the beams start at -π and do not repeat the first one at +π.

    Thread contract: not thread-safe; the simulation loop calls :meth:`scan`.

    Raises:
        ValueError: ``beams`` < 1, a ``fov`` outside (0, 2π], ranges not 0 <= min < max,
            a rate not > 0, or a negative noise (each message names the parameter).
    """

    def __init__(
        self,
        beams: int = 360,
        fov: float = 2.0 * math.pi,
        min_range: float = 0.12,
        max_range: float = 10.0,
        rate: float = 10.0,
        range_noise_std: float = 0.01,
        rng: np.random.Generator | None = None,
    ) -> None:
        if int(beams) < 1:
            raise ValueError(f"LaserScanner: beams must be >= 1, got {beams}")
        if not (0.0 < fov <= 2.0 * math.pi + 1e-9):
            raise ValueError(f"LaserScanner: fov must be in (0, 2*pi], got {fov}")
        if not (0.0 <= min_range < max_range and math.isfinite(max_range)):
            raise ValueError(
                f"LaserScanner: need 0 <= min_range ({min_range}) < max_range ({max_range})"
            )
        if not (math.isfinite(rate) and rate > 0.0):
            raise ValueError(f"LaserScanner: rate must be finite and > 0, got {rate}")
        if not (math.isfinite(range_noise_std) and range_noise_std >= 0.0):
            raise ValueError(f"LaserScanner: range_noise_std must be >= 0, got {range_noise_std}")
        self.beams = int(beams)
        self.fov = float(fov)
        self.min_range = float(min_range)
        self.max_range = float(max_range)
        self.rate = float(rate)
        self.range_noise_std = float(range_noise_std)
        self._rng = rng if rng is not None else np.random.default_rng()
        full_circle = self.fov >= 2.0 * math.pi - 1e-9
        if full_circle:
            self.angle_min = -math.pi
            self.angle_increment = 2.0 * math.pi / self.beams
        else:
            self.angle_min = -0.5 * self.fov
            self.angle_increment = self.fov / (self.beams - 1) if self.beams > 1 else 0.0
        self.angles = self.angle_min + self.angle_increment * np.arange(self.beams)
        self.angle_max = float(self.angles[-1])

    @property
    def period(self) -> float:
        """Seconds between scans."""
        return 1.0 / self.rate

    def scan(
        self,
        world: World,
        x: float,
        y: float,
        yaw: float,
        obstacles: Sequence[MovingObstacle] = (),
        stretch: np.ndarray | None = None,
    ) -> np.ndarray:
        """Ranges (m, float64, ``(beams,)``) seen from scanner pose ``(x, y, yaw)`` in the world.

        ``stretch`` (``(beams,)``, >= 1): each beam's length per metre of its horizontal
        advance, for a scan plane that is not level (a robot on a ramp); None: level."""
        directions = self.angles + yaw
        ranges = cast_rays_grid(world, x, y, directions, self.max_range)
        if obstacles:
            centres = np.array([o.position for o in obstacles], dtype=float)
            radii = np.array([o.radius for o in obstacles], dtype=float)
            ranges = np.minimum(ranges, cast_rays_discs(x, y, directions, centres, radii))
        if stretch is not None:
            ranges = ranges * stretch
        finite = np.isfinite(ranges)
        if self.range_noise_std > 0.0:
            ranges[finite] += self._rng.normal(0.0, self.range_noise_std, int(finite.sum()))
        ranges[finite & (ranges > self.max_range)] = np.inf
        ranges[finite & (ranges < self.min_range)] = -np.inf
        return ranges
