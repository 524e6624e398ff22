"""MovingObstacle: a disc walking back and forth along waypoints (a person, a cart)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


class MovingObstacle:
    """A disc of ``radius`` moving at ``speed`` along ``waypoints``, then back, forever.

    The motion is a function of travelled distance, so :meth:`position_after` can preview a
    step without moving; the simulation uses it to make the obstacle wait instead of walking
    into the robot, like a polite pedestrian.

    Thread contract: not thread-safe; the simulation loop owns it.

    Raises:
        ValueError: fewer than two waypoints, a non-finite waypoint, two identical consecutive
            waypoints, or a radius / speed that is not finite and > 0 (speed may be 0).
    """

    def __init__(
        self,
        waypoints: Sequence[Sequence[float]],
        radius: float = 0.25,
        speed: float = 0.4,
        name: str = "",
    ) -> None:
        points = np.asarray(waypoints, dtype=float)
        if points.ndim != 2 or points.shape[0] < 2 or points.shape[1] != 2:
            raise ValueError(
                f"MovingObstacle {name!r}: need at least two [x, y] waypoints, got {waypoints!r}"
            )
        if not np.all(np.isfinite(points)):
            raise ValueError(f"MovingObstacle {name!r}: waypoints must be finite")
        lengths = np.hypot(*np.diff(points, axis=0).T)
        if np.any(lengths <= 0.0):
            raise ValueError(f"MovingObstacle {name!r}: consecutive waypoints must differ")
        if not (math.isfinite(radius) and radius > 0.0):
            raise ValueError(f"MovingObstacle {name!r}: radius must be > 0, got {radius}")
        if not (math.isfinite(speed) and speed >= 0.0):
            raise ValueError(f"MovingObstacle {name!r}: speed must be >= 0, got {speed}")
        self.name = name
        self.waypoints = points
        self.radius = float(radius)
        self.speed = float(speed)
        self._cumulative = np.concatenate(([0.0], np.cumsum(lengths)))
        self._travelled = 0.0
        self.position = tuple(points[0])

    @property
    def track_length(self) -> float:
        """Length of one way along the waypoints (m)."""
        return float(self._cumulative[-1])

    def observe(self, time: float, robot_x: float, robot_y: float) -> None:
        """Called by the simulation before each step with the simulated time and the robot's
        true position. A plain obstacle ignores it; a :class:`ScriptedObstacle` starts walking
        from it.
        """

    def position_after(self, dt: float) -> tuple[float, float]:
        """Where the obstacle would be after ``dt`` more seconds of walking."""
        return self._position_at(self._travelled + self.speed * dt)

    def advance(self, dt: float) -> None:
        """Walk for ``dt`` s."""
        self._travelled += self.speed * dt
        self.position = self._position_at(self._travelled)

    def _position_at(self, travelled: float) -> tuple[float, float]:
        length = self.track_length
        # Back and forth: fold the distance into [0, length].
        s = travelled % (2.0 * length)
        if s > length:
            s = 2.0 * length - s
        i = int(np.searchsorted(self._cumulative, s, side="right")) - 1
        i = min(max(i, 0), len(self.waypoints) - 2)
        seg = self._cumulative[i + 1] - self._cumulative[i]
        a = (s - self._cumulative[i]) / seg
        p = self.waypoints[i] + a * (self.waypoints[i + 1] - self.waypoints[i])
        return (float(p[0]), float(p[1]))
