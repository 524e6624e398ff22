"""Fleet: several robots in one world, each a :class:`Simulation`, stepped together."""

from __future__ import annotations

import math
from collections.abc import Sequence

from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.simulation import Simulation, move_obstacles


class PeerRobot:
    """Another robot of the fleet as a disc, seen by a robot's laser and bumper.

    Quacks like a :class:`MovingObstacle` for the ray casters and the collision checker
    (``position``, ``radius``, ``name``): ``position`` is the other robot's true position now.

    Thread contract: read in the simulation loop only.
    """

    def __init__(self, simulation: Simulation, name: str) -> None:
        self.simulation = simulation
        self.name = name

    @property
    def position(self) -> tuple[float, float]:
        robot = self.simulation.robot
        return (robot.x, robot.y)

    @property
    def radius(self) -> float:
        return self.simulation.checker.robot_radius


class Fleet:
    """Robots ``simulations`` (one :class:`Simulation` each, same world, same step) stepped
    in lock step under names ``names``.

    Each robot's laser (and 3D lidar) sees the other robots as discs of their radius, and its
    bumper stops it before it enters one: the collision is recorded in its own
    ``checker.collisions`` (and recorder) ``with`` the other robot's name. One :meth:`step`:
    every robot takes its inputs and moves, in order (a robot checks against the positions the
    earlier ones reached in this step), then the moving obstacles walk (waiting for every
    robot), then each robot's clock, collisions, ground truth and sensors, in order. The moving
    obstacles are ``obstacles``: they are shared, every robot sees and hits the same ones (give
    the simulations none of their own).

    One robot alone steps exactly like its :class:`Simulation`.

    Thread contract: :meth:`step` in one thread (the simulation loop), like
    :meth:`Simulation.step`; each simulation's inputs may be set from any thread.

    Raises:
        ValueError: no robot, names not one per robot or not unique, different steps or
            worlds, a simulation with moving obstacles of its own, or robots that overlap at
            the start (names both).
    """

    def __init__(
        self,
        simulations: Sequence[Simulation],
        names: Sequence[str],
        obstacles: Sequence[MovingObstacle] = (),
    ) -> None:
        self.simulations = list(simulations)
        self.names = [str(n) for n in names]
        if not self.simulations:
            raise ValueError("Fleet: needs at least one robot")
        if len(self.names) != len(self.simulations) or len(set(self.names)) != len(self.names):
            raise ValueError(f"Fleet: need one unique name per robot, got {self.names}")
        first = self.simulations[0]
        for name, sim in zip(self.names, self.simulations, strict=True):
            if not math.isclose(sim.step_size, first.step_size, rel_tol=1e-12):
                raise ValueError(
                    f"Fleet: robot {name!r} steps {sim.step_size} s, robot "
                    f"{self.names[0]!r} {first.step_size} s: one step for the whole world"
                )
            if sim.world is not first.world:
                raise ValueError(f"Fleet: robot {name!r} is in another world")
            if sim.obstacles:
                raise ValueError(
                    f"Fleet: robot {name!r} has moving obstacles of its own; give them to the fleet"
                )
        self.obstacles = list(obstacles)
        for name, sim in zip(self.names, self.simulations, strict=True):
            sim.obstacles = self.obstacles
            sim.peers = [
                PeerRobot(other, other_name)
                for other_name, other in zip(self.names, self.simulations, strict=True)
                if other is not sim
            ]
            robot = sim.robot
            what = sim.checker.colliding_with(robot.x, robot.y, sim.obstacles + sim.peers)
            if what is not None:
                raise ValueError(
                    f"Fleet: the start pose ({robot.x:.3f}, {robot.y:.3f}) of robot {name!r} "
                    f"overlaps {what}"
                )

    @property
    def step_size(self) -> float:
        """Simulated seconds per step."""
        return self.simulations[0].step_size

    @property
    def time(self) -> float:
        """Simulated time (s) at the end of the last step."""
        return self.simulations[0].time

    @property
    def steps(self) -> int:
        """Steps taken."""
        return self.simulations[0].steps

    def simulation(self, name: str) -> Simulation:
        """The robot called ``name``.

        Raises:
            KeyError: no robot of that name.
        """
        try:
            return self.simulations[self.names.index(name)]
        except ValueError:
            raise KeyError(f"Fleet: no robot {name!r} (robots: {self.names})") from None

    def step(self) -> None:
        """Advance every robot and obstacle one step (see the class documentation)."""
        now = self.time
        moved = [sim._move_robot() for sim in self.simulations]
        move_obstacles(
            self.obstacles,
            [(sim.robot, sim.checker.robot_radius) for sim in self.simulations],
            now,
            self.step_size,
        )
        for sim, result in zip(self.simulations, moved, strict=True):
            sim._finish_step(*result)

    def run_for(self, duration: float) -> None:
        """Step for ``duration`` simulated seconds (tests and offline runs)."""
        for _ in range(int(round(duration / self.step_size))):
            self.step()
