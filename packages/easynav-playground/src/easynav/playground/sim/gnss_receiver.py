"""GnssReceiver: simulated GNSS fixes (noise, occasional jumps, outages) around a geodetic
origin."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GnssFix:
    """One fix: ``latitude``/``longitude`` (degrees), ``altitude`` (m), the standard deviation
    the receiver declares (``std``, m, horizontal), and ``status`` (-1: no fix, 0: fix).
    ``jump`` marks a fix the simulation displaced on purpose (a multipath outlier)."""

    stamp: float
    latitude: float
    longitude: float
    altitude: float
    std: float
    status: int
    jump: bool = False


class GnssReceiver:
    """Fixes of the robot's true map position at ``rate`` Hz (1–10 Hz).

    The map frame's origin is at geodetic ``origin`` ``(lat, lon, alt)``, x east, y north; map
    positions become latitude/longitude through UTM (pyproj, the origin's zone). Each fix adds
    N(0, ``noise``²) per axis; with probability ``jump_probability`` a fix is displaced by
    ``jump_distance`` m in a random direction; during an ``outages`` window ``(start, end)``
    (simulated s) the receiver reports no fix.

    Thread contract: not thread-safe; the simulation loop owns it.

    Raises:
        ValueError: a rate outside 1–10 Hz, a negative noise, a probability outside [0, 1], a
            malformed outage or origin. ImportError naming the extra without pyproj.
    """

    def __init__(self, origin: Sequence[float], rate: float = 5.0, noise: float = 0.3,
                 jump_probability: float = 0.0, jump_distance: float = 30.0,
                 outages: Sequence[Sequence[float]] = (),
                 rng: np.random.Generator | None = None) -> None:
        if not (math.isfinite(rate) and 1.0 <= rate <= 10.0):
            raise ValueError(f"GnssReceiver: rate must be in [1, 10] Hz, got {rate}")
        if not (math.isfinite(noise) and noise >= 0.0):
            raise ValueError(f"GnssReceiver: noise must be finite and >= 0, got {noise}")
        if not (0.0 <= jump_probability <= 1.0):
            raise ValueError(f"GnssReceiver: jump_probability must be in [0, 1], got "
                             f"{jump_probability}")
        windows = []
        for window in outages:
            if len(window) != 2 or not window[0] <= window[1]:
                raise ValueError(f"GnssReceiver: an outage must be [start, end], got {window!r}")
            windows.append((float(window[0]), float(window[1])))
        if len(origin) != 3:
            raise ValueError(f"GnssReceiver: origin must be [lat, lon, alt], got {origin!r}")
        try:
            from easynav.localizers.fusion.utm_projection import UtmProjection
        except ImportError as exc:
            raise ImportError("simulated GNSS needs pyproj and easynav-localizers: "
                              "pip install easynav-playground[gnss]") from exc
        self.projection = UtmProjection(float(origin[0]), float(origin[1]), float(origin[2]))
        self.rate = float(rate)
        self.period = 1.0 / self.rate
        self.noise = float(noise)
        self.jump_probability = float(jump_probability)
        self.jump_distance = float(jump_distance)
        self.outages = windows
        self._rng = rng if rng is not None else np.random.default_rng()

    def in_outage(self, stamp: float) -> bool:
        """Whether ``stamp`` falls in an outage window."""
        return any(start <= stamp < end for start, end in self.outages)

    def fix(self, stamp: float, x: float, y: float) -> GnssFix:
        """The fix at ``stamp`` of a robot truly at map ``(x, y)``."""
        alt = self.projection.altitude
        if self.in_outage(stamp):
            return GnssFix(stamp, math.nan, math.nan, math.nan, self.noise, -1)
        rng = self._rng
        ex, ey = rng.normal(0.0, self.noise, 2) if self.noise > 0.0 else (0.0, 0.0)
        jump = bool(self.jump_probability > 0.0 and rng.random() < self.jump_probability)
        if jump:
            angle = rng.uniform(-math.pi, math.pi)
            ex += self.jump_distance * math.cos(angle)
            ey += self.jump_distance * math.sin(angle)
        lat, lon = self.projection.inverse(x + ex, y + ey)
        return GnssFix(stamp, lat, lon, alt, self.noise, 0, jump)

    def to_latlon(self, x: float, y: float) -> tuple[float, float]:
        """Latitude and longitude of map point ``(x, y)``."""
        return self.projection.inverse(x, y)
