"""DistanceTracker: the distance a robot has covered, from its sampled positions."""

from __future__ import annotations

import math


class DistanceTracker:
    """Sums the xy path length of a sequence of positions, ignoring localisation jitter.

    A position is counted only once it is ``min_step`` (m) away from the last counted one, so
    a localizer trembling by a few millimetres around a standing robot adds nothing, while real
    motion is counted in full (the path is measured as a polyline of ``min_step`` chords: on a
    curve of radius r it is short by about ``min_step² / (24 r²)`` of its length, negligible).

    Thread contract: one thread (the goal manager's, under its lock).
    """

    def __init__(self, min_step: float = 0.01) -> None:
        if not (math.isfinite(min_step) and min_step >= 0.0):
            raise ValueError(f"DistanceTracker min_step must be finite and >= 0, got {min_step!r}")
        self.min_step = min_step
        self.total = 0.0
        self._anchor: tuple[float, float] | None = None

    def reset(self) -> None:
        """Forget the distance and the last position."""
        self.total = 0.0
        self._anchor = None

    def add(self, x: float, y: float) -> float:
        """Take a new position; returns the total distance (m). Non-finite positions are not
        counted (a localizer's bad sample must not jump the odometer).
        """
        if not (math.isfinite(x) and math.isfinite(y)):
            return self.total
        if self._anchor is None:
            self._anchor = (x, y)
            return self.total
        step = math.hypot(x - self._anchor[0], y - self._anchor[1])
        if step >= self.min_step:
            self.total += step
            self._anchor = (x, y)
        return self.total
