"""Lidar3D: a multi-ring 3D lidar ray-cast against walls, furniture boxes, floor and people."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from easynav.playground.sim.box_obstacle import BoxObstacle
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.ray_casting import cast_rays_discs, cast_rays_grid
from easynav.playground.sim.world import World


class Lidar3D:
    """``rings`` beams spread evenly over elevations ``[min_elevation, max_elevation]`` (rad),
    each turning through ``beams`` azimuths over 360°, returning points up to ``max_range``.

    What a beam hits: the world grid's walls (any height), furniture boxes (their height range),
    the floor (z 0) and moving obstacles (vertical cylinders up to 1.8 m). Beams with nothing
    within ``[min_range, max_range]`` return no point. Ranges carry Gaussian noise
    ``noise_std`` (m).

    Thread contract: not thread-safe; the simulation loop calls :meth:`scan`.

    Raises:
        ValueError: fewer than 1 ring or beam, elevations not ``-π/2 < min <= max < π/2``,
            ranges not ``0 <= min < max``, rate or noise out of range (names the parameter).
    """

    PERSON_HEIGHT = 1.8

    def __init__(
        self,
        rings: int = 16,
        beams: int = 180,
        min_elevation: float = -0.26,
        max_elevation: float = 0.26,
        min_range: float = 0.2,
        max_range: float = 8.0,
        rate: float = 5.0,
        noise_std: float = 0.01,
        rng: np.random.Generator | None = None,
    ) -> None:
        if int(rings) < 1 or int(beams) < 1:
            raise ValueError(f"Lidar3D: rings and beams must be >= 1, got {rings}, {beams}")
        if not (-math.pi / 2 < min_elevation <= max_elevation < math.pi / 2):
            raise ValueError(
                f"Lidar3D: need -pi/2 < min_elevation ({min_elevation}) <= max_elevation "
                f"({max_elevation}) < pi/2"
            )
        if not (0.0 <= min_range < max_range and math.isfinite(max_range)):
            raise ValueError(
                f"Lidar3D: need 0 <= min_range ({min_range}) < max_range ({max_range})"
            )
        if not (math.isfinite(rate) and rate > 0.0):
            raise ValueError(f"Lidar3D: rate must be finite and > 0, got {rate}")
        if not (math.isfinite(noise_std) and noise_std >= 0.0):
            raise ValueError(f"Lidar3D: noise_std must be >= 0, got {noise_std}")
        self.rings, self.beams = int(rings), int(beams)
        self.min_range, self.max_range = float(min_range), float(max_range)
        self.rate, self.noise_std = float(rate), float(noise_std)
        self.elevations = (
            np.linspace(min_elevation, max_elevation, self.rings)
            if self.rings > 1 else np.array([0.5 * (min_elevation + max_elevation)])
        )
        self.azimuths = -math.pi + 2.0 * math.pi / self.beams * np.arange(self.beams)
        self._rng = rng if rng is not None else np.random.default_rng()

    @property
    def period(self) -> float:
        """Seconds between scans."""
        return 1.0 / self.rate

    def scan(
        self,
        world: World,
        boxes: Sequence[BoxObstacle],
        x: float,
        y: float,
        z: float,
        yaw: float,
        obstacles: Sequence[MovingObstacle] = (),
    ) -> np.ndarray:
        """Points ``(N, 3)`` in the sensor frame (x forward, z up) seen from ``(x, y, z, yaw)``."""
        azimuths = np.tile(self.azimuths, self.rings)
        elevations = np.repeat(self.elevations, self.beams)
        cos_e, sin_e = np.cos(elevations), np.sin(elevations)
        directions = azimuths + yaw
        # Walls are full height: the horizontal distance to them, along the beam's slant.
        flat = cast_rays_grid(world, x, y, self.azimuths + yaw, self.max_range)
        ranges = np.tile(flat, self.rings) / cos_e
        with np.errstate(divide="ignore"):
            floor = np.where(sin_e < 0.0, z / -sin_e, np.inf)
        ranges = np.minimum(ranges, floor)
        if boxes:
            ranges = np.minimum(ranges, _boxes_range(boxes, x, y, z, directions, cos_e, sin_e))
        if obstacles:
            centres = np.array([o.position for o in obstacles], dtype=float)
            radii = np.array([o.radius for o in obstacles], dtype=float)
            horizontal = cast_rays_discs(x, y, self.azimuths + yaw, centres, radii)
            slant = np.tile(horizontal, self.rings) / cos_e
            hit_z = z + slant * sin_e
            ranges = np.where((hit_z <= self.PERSON_HEIGHT) & (slant < ranges), slant, ranges)
        keep = np.isfinite(ranges) & (ranges >= self.min_range) & (ranges <= self.max_range)
        r = ranges[keep]
        if self.noise_std > 0.0:
            r = r + self._rng.normal(0.0, self.noise_std, r.size)
        a, ce, se = azimuths[keep], cos_e[keep], sin_e[keep]
        return np.column_stack((r * ce * np.cos(a), r * ce * np.sin(a), r * se))


def _boxes_range(boxes, x, y, z, directions, cos_e, sin_e) -> np.ndarray:
    """Distance along each beam to the nearest box (slab method), ``inf`` when none."""
    d = np.stack((np.cos(directions) * cos_e, np.sin(directions) * cos_e, sin_e), axis=1)
    low = np.array([(b.x0, b.y0, b.z0) for b in boxes])  # (M, 3)
    high = np.array([(b.x1, b.y1, b.z1) for b in boxes])
    origin = np.array([x, y, z])
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d  # (B, 3)
        t0 = (low[None, :, :] - origin) * inv[:, None, :]
        t1 = (high[None, :, :] - origin) * inv[:, None, :]
    # A beam parallel to a slab and outside it never enters: nan (0·inf) means outside there.
    t_near = np.nan_to_num(np.minimum(t0, t1), nan=np.inf).max(axis=2)
    t_far = np.nan_to_num(np.maximum(t0, t1), nan=-np.inf).min(axis=2)
    hit = (t_near <= t_far) & (t_far >= 0.0)
    t = np.where(hit, np.maximum(t_near, 0.0), np.inf)
    return t.min(axis=1)
