"""ScriptedObstacle: a disc that waits, then walks its waypoints (a person stepping out)."""

from __future__ import annotations

import math
from collections.abc import Sequence

from easynav.playground.sim.moving_obstacle import MovingObstacle


class ScriptedObstacle(MovingObstacle):
    """A :class:`MovingObstacle` that stands at its first waypoint until it is started, then
    walks along the waypoints at ``speed``, standing ``pause`` seconds at each intermediate one.

    It starts at the first step where both hold: the simulated time is at least ``start_time``,
    and, when ``start_distance`` is given, the robot's true centre is within ``start_distance``
    of the first waypoint (a person who steps out when the robot comes by). With ``repeat``
    False it walks the waypoints once and then stays at the last one; with ``repeat`` True it
    walks back and forth like a plain moving obstacle (no pauses then). Like every obstacle it
    waits rather than walk into the robot (the wait does not shorten a pause).

    :attr:`started_at` is the simulated time it started (None before).

    Thread contract: not thread-safe; the simulation loop owns it.

    Raises:
        ValueError: as :class:`MovingObstacle`, or a ``start_time`` or ``pause`` that is not
            finite and >= 0, a ``start_distance`` that is not finite and > 0, a ``pause`` with
            ``repeat``, or a zero ``speed`` (it would never walk).
    """

    def __init__(
        self,
        waypoints: Sequence[Sequence[float]],
        radius: float = 0.25,
        speed: float = 0.4,
        name: str = "",
        start_time: float = 0.0,
        start_distance: float | None = None,
        repeat: bool = False,
        pause: float = 0.0,
    ) -> None:
        super().__init__(waypoints, radius=radius, speed=speed, name=name)
        if not self.speed > 0.0:
            raise ValueError(f"ScriptedObstacle {name!r}: speed must be > 0, got {speed}")
        for label, value in (("start_time", start_time), ("pause", pause)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"ScriptedObstacle {name!r}: {label} must be >= 0, got {value}")
        if start_distance is not None and not (
            math.isfinite(start_distance) and start_distance > 0.0
        ):
            raise ValueError(
                f"ScriptedObstacle {name!r}: start_distance must be > 0, got {start_distance}"
            )
        if repeat and pause > 0.0:
            raise ValueError(f"ScriptedObstacle {name!r}: pause is for a single walk, not repeat")
        self.start_time = float(start_time)
        self.start_distance = None if start_distance is None else float(start_distance)
        self.repeat = bool(repeat)
        self.pause = float(pause)
        self.started_at: float | None = None
        self._walk_time = 0.0  # time spent on the walk (walking or pausing), not waiting

    @property
    def started(self) -> bool:
        """True once it started walking."""
        return self.started_at is not None

    def observe(self, time: float, robot_x: float, robot_y: float) -> None:
        """Start when the time and the robot's distance to the first waypoint say so."""
        if self.started or time < self.start_time:
            return
        if self.start_distance is not None:
            x0, y0 = self.waypoints[0]
            if math.hypot(robot_x - x0, robot_y - y0) > self.start_distance:
                return
        self.started_at = float(time)

    def position_after(self, dt: float) -> tuple[float, float]:
        if not self.started:
            return self.position
        return self._position_at(self._distance_at(self._walk_time + dt))

    def advance(self, dt: float) -> None:
        if not self.started:
            return
        self._walk_time += dt
        self._travelled = self._distance_at(self._walk_time)
        self.position = self._position_at(self._travelled)

    def _distance_at(self, walk_time: float) -> float:
        """Distance along the waypoints after ``walk_time`` s of walking and pausing."""
        if self.repeat:
            return self.speed * walk_time
        # Hand-written schedule (a few segments): walk each leg, then pause unless it was the
        # last; past the end it stays at the last waypoint (the fold in _position_at would
        # send it back).
        remaining = walk_time
        lengths = self._cumulative[1:] - self._cumulative[:-1]
        for i, length in enumerate(lengths):
            leg_time = float(length) / self.speed
            if remaining <= leg_time:
                return float(self._cumulative[i]) + self.speed * remaining
            remaining -= leg_time
            if i < len(lengths) - 1:
                if remaining <= self.pause:
                    return float(self._cumulative[i + 1])
                remaining -= self.pause
        return self.track_length
