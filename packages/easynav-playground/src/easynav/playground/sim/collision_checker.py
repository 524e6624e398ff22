"""CollisionChecker: the robot disc against the world grid and the moving obstacles."""

from __future__ import annotations

import math
from collections.abc import Sequence

from easynav.playground.sim.collision import Collision
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.world import World


class CollisionChecker:
    """Tests the robot's footprint (a disc of ``robot_radius``) and records collisions.

    A collision is recorded once per contact: while the robot keeps pushing against the same
    thing no new record is made; touching again after getting ``release_distance`` (0.05 m)
    clear counts again.

    Thread contract: not thread-safe; the simulation loop calls :meth:`check` and
    :meth:`record`; other threads read :attr:`collisions` only through ``Simulation``.

    Raises:
        ValueError: ``robot_radius`` not finite and > 0.
    """

    def __init__(self, world: World, robot_radius: float = 0.2) -> None:
        if not (math.isfinite(robot_radius) and robot_radius > 0.0):
            raise ValueError(f"CollisionChecker: robot_radius must be > 0, got {robot_radius}")
        self.world = world
        self.robot_radius = float(robot_radius)
        self.collisions: list[Collision] = []
        self._in_contact = False
        self.release_distance = 0.05

    def clearance(
        self, x: float, y: float, obstacles: Sequence[MovingObstacle] = (), horizon: float = 2.0
    ) -> float:
        """Gap (m) between the robot disc at ``(x, y)`` and the nearest wall or obstacle.

        Negative when overlapping; capped at ``horizon`` (nothing nearer than that).
        """
        reach = self.robot_radius + horizon
        nearest = self.world.distance_to_occupied(x, y, reach)
        for o in obstacles:
            nearest = min(nearest, math.hypot(x - o.position[0], y - o.position[1]) - o.radius)
        return min(nearest - self.robot_radius, horizon)

    def colliding_with(
        self, x: float, y: float, obstacles: Sequence[MovingObstacle] = (), margin: float = 0.0
    ) -> str | None:
        """What the robot disc at ``(x, y)``, grown by ``margin``, overlaps: ``"wall"``, an
        obstacle's name, or None."""
        radius = self.robot_radius + margin
        if self.world.distance_to_occupied(x, y, radius) < radius:
            return "wall"
        for i, o in enumerate(obstacles):
            gap = math.hypot(x - o.position[0], y - o.position[1]) - o.radius - radius
            if gap < 0.0:
                return o.name or f"obstacle {i}"
        return None

    def record(
        self,
        stamp: float,
        x: float,
        y: float,
        with_what: str | None,
        obstacles: Sequence[MovingObstacle] = (),
    ) -> Collision | None:
        """Note the contact state at ``stamp``; returns the new Collision when one starts.

        A contact ends only once the robot is :attr:`release_distance` clear of everything:
        a base creeping forward against a wall is one collision, not one per bump.
        """
        if with_what is None:
            if self._in_contact and (
                self.colliding_with(x, y, obstacles, self.release_distance) is None
            ):
                self._in_contact = False
            return None
        if self._in_contact:
            return None
        self._in_contact = True
        collision = Collision(stamp, x, y, with_what)
        self.collisions.append(collision)
        return collision
