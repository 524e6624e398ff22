"""sensor_msgs/LaserScan -> points, vectorised, with the beam directions cached per sensor."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from easynav.system.sensors.errors import PerceptionConversionError


@dataclass(frozen=True, slots=True)
class ScanConversionStats:
    """How many ranges of one scan were dropped, and why."""

    beams: int
    not_finite: int
    out_of_range: int
    #: Of ``not_finite``, the ±inf readings: REP 117's "no return" (+inf) and "too close"
    #: (-inf), what a conforming driver publishes in an open space; the rest are NaN (errors).
    infinite: int = 0

    @property
    def dropped(self) -> int:
        """Ranges that did not become points."""
        return self.not_finite + self.out_of_range

    @property
    def invalid(self) -> int:
        """Dropped readings that are not REP 117 values: NaN and finite ranges outside
        ``[range_min, range_max]`` (a driver or a cable problem worth a warning)."""
        return self.not_finite - self.infinite + self.out_of_range


class LaserScanConverter:
    """Turns scans into ``(N, 3)`` float64 points in the scan frame (z = 0).

    A range becomes a point when it is finite and within ``[range_min, range_max]``; NaN, ±inf
    (REP 117: no return / too close) and out-of-range readings are dropped and counted in the
    returned :class:`ScanConversionStats`. The cosines and sines of the beam angles are computed
    once per scan geometry (a sensor keeps its geometry), so a conversion is a few vector ops.

    Thread contract: one converter per sensor, used by the thread that runs its callback.
    Exceptions: :class:`PerceptionConversionError` for a scan whose geometry is not finite or
    whose ``range_min > range_max``.
    """

    def __init__(self) -> None:
        self._geometry: tuple[int, float, float] | None = None
        self._cos = np.empty(0)
        self._sin = np.empty(0)

    def convert(self, msg: Any) -> tuple[np.ndarray, ScanConversionStats]:
        """Points and drop statistics of one LaserScan message."""
        ranges = np.asarray(msg.ranges, dtype=np.float32)
        n = ranges.shape[0]
        angle_min = float(msg.angle_min)
        increment = float(msg.angle_increment)
        range_min = float(msg.range_min)
        range_max = float(msg.range_max)
        if not (math.isfinite(angle_min) and math.isfinite(increment)):
            raise PerceptionConversionError(
                f"LaserScan angle_min = {angle_min}, angle_increment = {increment} are not finite"
            )
        if math.isnan(range_min) or math.isnan(range_max) or range_min > range_max:
            raise PerceptionConversionError(
                f"LaserScan range_min = {range_min}, range_max = {range_max}: not a valid range"
            )
        geometry = (n, angle_min, increment)
        if geometry != self._geometry:
            angles = angle_min + increment * np.arange(n, dtype=np.float64)
            self._cos = np.cos(angles)
            self._sin = np.sin(angles)
            self._geometry = geometry
        finite = np.isfinite(ranges)
        keep = finite & (ranges >= range_min) & (ranges <= range_max)
        kept = int(np.count_nonzero(keep))
        not_finite = n - int(np.count_nonzero(finite))
        infinite = int(np.count_nonzero(np.isinf(ranges))) if not_finite else 0
        stats = ScanConversionStats(n, not_finite, n - kept - not_finite, infinite)
        points = np.zeros((kept, 3), dtype=np.float64)
        if kept == n:
            r = ranges.astype(np.float64)
            np.multiply(r, self._cos, out=points[:, 0])
            np.multiply(r, self._sin, out=points[:, 1])
        else:
            r = ranges[keep].astype(np.float64)
            np.multiply(r, self._cos[keep], out=points[:, 0])
            np.multiply(r, self._sin[keep], out=points[:, 1])
        return points, stats
