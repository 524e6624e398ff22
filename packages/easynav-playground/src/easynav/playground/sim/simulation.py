"""Simulation: the fixed-step engine that moves the robot and produces its sensor data."""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence

import numpy as np

from easynav.playground.sim.box_obstacle import BoxObstacle, rasterize_boxes
from easynav.playground.sim.collision import Collision
from easynav.playground.sim.collision_checker import CollisionChecker
from easynav.playground.sim.diff_drive_robot import DiffDriveRobot
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.sim.laser_scanner import LaserScanner
from easynav.playground.sim.lidar_3d import Lidar3D
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.multilevel import MultiLevelWorld
from easynav.playground.sim.terrain import Terrain
from easynav.playground.sim.wheel_odometry import WheelOdometry
from easynav.playground.sim.world import World

ScanCallback = Callable[[float, np.ndarray], None]
StampCallback = Callable[[float], None]
CollisionCallback = Callable[[Collision], None]
CloudCallback = Callable[[float, np.ndarray], None]


class Simulation:
    """World + robot + sensors advanced in fixed steps of ``step`` simulated seconds.

    Each :meth:`step`: take the latest velocity command, ramp and integrate the robot, stop it
    instead of entering a wall or an obstacle (a collision is recorded), move the obstacles
    (they wait rather than walk into the robot; each first :meth:`~MovingObstacle.observe` s the
    time and the robot), feed the odometry the true motion, and call
    the sensor callbacks that are due: ``on_scan(stamp, ranges)`` at the scanner rate,
    ``on_odometry(stamp)`` at ``odom_rate``; ``on_collision(collision)`` when one starts.
    Stamps are simulated time at the end of the step.

    A robot :attr:`held` in place (:meth:`set_held`, wheels blocked: a test scenario) does not
    move whatever it is commanded; its velocities are zero and the odometry sees no motion.
    Commands are still taken, so it drives on when released. :attr:`hold_events` lists
    ``(stamp, held)`` for every change, stamped with the first step it applied to.
    :attr:`command_events` lists ``(stamp, v, w, received)`` of every command the robot took:
    the step it applied to (simulated time), the values after clamping, and the wall-clock time
    (``time.time()``) the driver received it, when given: what reached the robot and when, in
    both clocks (a process's view of simulated time lags on a loaded machine; the wall clock
    of one machine does not).

    :meth:`teleport` carries the robot to another pose at the next step, stopped, without the
    wheels turning (a kidnapped robot: the odometry sees nothing); a pose in collision is
    refused. :attr:`teleport_events` lists ``(stamp, x, y, yaw, accepted)``.

    The laser is mounted at ``laser_offset`` ``(x, y, yaw)`` in the robot frame, at height
    ``laser_height``. Furniture ``boxes`` (:class:`BoxObstacle`) have heights: the laser sees
    those crossing its plane, the robot hits those reaching below ``robot_height`` (the world
    grid's walls are full height for both). An optional 3D ``lidar`` (:class:`Lidar3D`) at
    ``lidar_offset`` ``(x, y, z, yaw)`` sees everything; ``on_cloud(stamp, points)`` gets its
    points in the lidar frame at its rate.

    On a world with a ``terrain`` (:class:`Terrain`: ground heights) the wheels' motion is
    laid on the ground (on a slope the horizontal advance shrinks by the cosine of the pitch),
    and the robot cannot climb ground steeper than the terrain's ``max_climb_slope``: it stops
    where it is, like at a wall, and a collision ``with`` ``"steep slope (S deg > LIMIT)"`` is
    recorded once per stop (a new one after it moved :attr:`SLOPE_RELEASE` m). The recorder gets the
    height and slope under the robot with every true pose (:meth:`GroundTruthRecorder.
    record_terrain`). Without a terrain nothing of this applies (flat worlds).

    On a multi-level world (``levels``: :class:`MultiLevelWorld`, floors joined by ramps) the
    robot is on one level at a time (:attr:`level`, starting on ``start_level``, default the
    world's): it changes level only across a ramp's foot or top edge
    (:meth:`MultiLevelWorld.next_level`), its height :attr:`z` and attitude (:attr:`pitch`,
    :attr:`roll`) follow that level's surface, its motion is laid on the surface as on a
    terrain, it hits the walls of its level (:meth:`MultiLevelWorld.collision_world`; a move off
    its level's area is refused as ``"edge of LEVEL"``) and its laser sees what the scan plane of
    its level meets (:meth:`MultiLevelWorld.laser_world`; ``world``, ``boxes`` and
    ``laser_height``/``robot_height`` are then not used: the levels carry their own). A ramp
    steeper than the world's climb limit stops the robot as a too-steep terrain does. The recorder
    gets ``(stamp, level, z, pitch)`` with every true pose (:meth:`GroundTruthRecorder.
    record_level`) and the height and slope as on a terrain. :attr:`level_events` lists
    ``(stamp, level)`` at every change.

    Thread contract: :meth:`step` and the callbacks run in one thread (the simulation loop);
    :meth:`set_command`, :meth:`set_held` and :meth:`teleport` may be called from any thread
    (they only store under a lock).

    Raises:
        ValueError: a step or rate not finite and > 0, or a start pose in collision.
    """

    #: m the robot must move from where a slope stopped it before another stop is recorded.
    SLOPE_RELEASE = 0.05

    def __init__(
        self,
        world: World,
        robot: DiffDriveRobot,
        scanner: LaserScanner,
        odometry: WheelOdometry,
        obstacles: Sequence[MovingObstacle] = (),
        robot_radius: float = 0.2,
        step: float = 0.005,
        odom_rate: float = 50.0,
        laser_offset: tuple[float, float, float] = (0.1, 0.0, 0.0),
        recorder: GroundTruthRecorder | None = None,
        boxes: Sequence[BoxObstacle] = (),
        robot_height: float = 0.5,
        laser_height: float = 0.25,
        lidar: Lidar3D | None = None,
        lidar_offset: tuple[float, float, float, float] = (0.0, 0.0, 0.45, 0.0),
        terrain: Terrain | None = None,
        levels: MultiLevelWorld | None = None,
        start_level: str | None = None,
    ) -> None:
        for name, value in (("step", step), ("odom_rate", odom_rate)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"Simulation: {name} must be finite and > 0, got {value}")
        self.world = world
        self.boxes = list(boxes)
        # What the 2D laser sees and what the robot's body hits (walls are full height).
        self.laser_world = rasterize_boxes(world, self.boxes, laser_height, laser_height)
        self.collision_world = rasterize_boxes(world, self.boxes, 0.0, robot_height)
        self.robot = robot
        self.scanner = scanner
        self.lidar = lidar
        self.lidar_offset = tuple(float(v) for v in lidar_offset)
        self.odometry = odometry
        self.obstacles = list(obstacles)
        #: The other robots as discs (:class:`~easynav.playground.sim.fleet.PeerRobot`), set
        #: by a :class:`~easynav.playground.sim.fleet.Fleet`; empty for a robot alone.
        self.peers: list = []
        self.levels = levels
        self.level: str | None = None
        self.level_events: list[tuple[float, str]] = []
        if levels is not None:
            if terrain is not None:
                raise ValueError("Simulation: a world has a terrain or levels, not both")
            self.level = start_level if start_level is not None else levels.start_level
            levels.surface(self.level)  # KeyError: an unknown level
            for name in levels.level_names:  # every level's grids now, not in the loop
                levels.collision_world(name)
                levels.laser_world(name)
            self.level_events.append((0.0, self.level))
            self.laser_world = levels.laser_world(self.level)
            self.collision_world = levels.collision_world(self.level)
        self.checker = CollisionChecker(self.collision_world, robot_radius)
        self.terrain = terrain
        self._slope_stop_at: tuple[float, float] | None = None
        self.step_size = float(step)
        self.odom_period = 1.0 / float(odom_rate)
        self.laser_offset = tuple(float(v) for v in laser_offset)
        self.recorder = recorder if recorder is not None else GroundTruthRecorder()
        self.time = 0.0
        self.steps = 0
        self.on_scan: list[ScanCallback] = []
        self.on_odometry: list[StampCallback] = []
        self.on_collision: list[CollisionCallback] = []
        self.on_cloud: list[CloudCallback] = []
        self._next_cloud = lidar.period if lidar is not None else math.inf
        self._command_lock = threading.Lock()
        self._pending_command: tuple[float, float] | None = None
        self._held = False
        self._was_held = False
        self.hold_events: list[tuple[float, bool]] = []
        self._pending_teleport: tuple[float, float, float] | None = None
        self.teleport_events: list[tuple[float, float, float, float, bool]] = []
        self.command_events: list[tuple[float, float, float]] = []
        self.commands_received = 0
        self._next_scan = scanner.period
        self._next_odom = self.odom_period
        # Further sensors (IMU, GNSS): [period, next due, callback(stamp)].
        self._periodic: list[list] = []
        what = self.checker.colliding_with(robot.x, robot.y, self.obstacles)
        if what is not None:
            raise ValueError(
                f"Simulation: the start pose ({robot.x:.3f}, {robot.y:.3f}) of a robot of radius "
                f"{robot_radius} m overlaps {what} in world '{world.name}'"
            )

    # ------------------------------------------------------------------ inputs
    def set_command(self, v: float, w: float, received: float | None = None) -> None:
        """Queue a velocity command; the next step applies it. ``received``: the wall-clock
        time the driver got it (kept in :attr:`command_events`).

        Raises:
            ValueError: ``v`` or ``w`` is NaN or infinite (nothing is queued).
        """
        if not (math.isfinite(v) and math.isfinite(w)):
            raise ValueError(f"Simulation: non-finite velocity command v={v}, w={w}")
        with self._command_lock:
            self._pending_command = (float(v), float(w), received)
            self.commands_received += 1

    def set_held(self, held: bool) -> None:
        """Hold the robot in place (True) or release it (False) from the next step on."""
        with self._command_lock:
            self._held = bool(held)

    def teleport(self, x: float, y: float, yaw: float) -> None:
        """Carry the robot to ``(x, y, yaw)`` at the next step (see the class documentation).

        Raises:
            ValueError: a value that is not finite.
        """
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(f"Simulation.teleport: pose ({x}, {y}, {yaw}) is not finite")
        with self._command_lock:
            self._pending_teleport = (float(x), float(y), float(yaw))

    @property
    def held(self) -> bool:
        """Whether the robot is held in place."""
        with self._command_lock:
            return self._held

    def add_periodic(self, period: float, callback: StampCallback) -> None:
        """Call ``callback(stamp)`` every ``period`` simulated seconds, after the step's motion
        (a sensor reading the robot's state: IMU, GNSS).

        Raises:
            ValueError: a period not finite and > 0.
        """
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError(f"Simulation: a period must be finite and > 0, got {period}")
        self._periodic.append([float(period), float(period), callback])

    # ------------------------------------------------------------------ state
    @property
    def z(self) -> float:
        """Height (m) of the ground under the robot: its level's surface on a multi-level
        world, the terrain's height, 0 on a flat world."""
        r = self.robot
        if self.levels is not None:
            return self.levels.height(self.level, r.x, r.y)
        if self.terrain is not None:
            return self.terrain.height(r.x, r.y)
        return 0.0

    @property
    def pitch(self) -> float:
        """The robot's pitch (rad, REP-103: negative nose up) on a multi-level world; 0
        elsewhere."""
        if self.levels is None:
            return 0.0
        return self.levels.attitude(self.level, self.robot.yaw)[0]

    @property
    def roll(self) -> float:
        """The robot's roll (rad, REP-103) on a multi-level world; 0 elsewhere."""
        if self.levels is None:
            return 0.0
        return self.levels.attitude(self.level, self.robot.yaw)[1]

    def laser_pose(self) -> tuple[float, float, float]:
        """World pose of the laser ``(x, y, yaw)``."""
        r = self.robot
        ox, oy, oyaw = self.laser_offset
        c, s = math.cos(r.yaw), math.sin(r.yaw)
        return (r.x + c * ox - s * oy, r.y + s * ox + c * oy, r.yaw + oyaw)

    def scan_now(self) -> np.ndarray:
        """Take a scan from the current pose (no scheduling, no callbacks)."""
        if self.levels is not None:
            # The laser pitches with the robot: along a slope a beam is longer than its
            # horizontal advance (the grid's distance).
            x, y, yaw = self.laser_pose()
            gx, gy = self.levels.surface(self.level).gradient()
            if gx or gy:
                directions = self.scanner.angles + yaw
                rise = gx * np.cos(directions) + gy * np.sin(directions)
                return self.scanner.scan(self.laser_world, x, y, yaw, self._others(),
                                         stretch=np.sqrt(1.0 + rise * rise))
        return self.scanner.scan(self.laser_world, *self.laser_pose(), self._others())

    def cloud_now(self) -> np.ndarray:
        """Take a 3D lidar scan from the current pose (lidar frame; needs a lidar)."""
        r = self.robot
        ox, oy, oz, oyaw = self.lidar_offset
        c, s = math.cos(r.yaw), math.sin(r.yaw)
        return self.lidar.scan(
            self.world, self.boxes, r.x + c * ox - s * oy, r.y + s * ox + c * oy, oz,
            r.yaw + oyaw, self._others(),
        )

    # ------------------------------------------------------------------ stepping
    def step(self) -> None:
        """Advance one fixed step (see the class documentation)."""
        now = self.time
        moved = self._move_robot()
        move_obstacles(self.obstacles, [(self.robot, self.checker.robot_radius)], now,
                       self.step_size)
        self._finish_step(*moved)

    def _others(self) -> list:
        """What this robot sees and hits besides the walls: the moving obstacles, then the
        other robots of a :class:`~easynav.playground.sim.fleet.Fleet` (discs)."""
        return self.obstacles + self.peers if self.peers else self.obstacles

    def _move_robot(self) -> tuple[str | None, float | None]:
        """First part of a step: take the inputs and move the robot (not the obstacles);
        returns what stopped it (or None) and the too-steep slope (or None)."""
        dt = self.step_size
        now = self.time
        others = self._others()
        with self._command_lock:
            command, self._pending_command = self._pending_command, None
            held = self._held
            teleport, self._pending_teleport = self._pending_teleport, None
        robot = self.robot
        if teleport is not None:
            tx, ty, tyaw = teleport
            accepted = self.checker.colliding_with(tx, ty, others) is None
            if accepted:
                robot.stop()
                robot.apply_state(tx, ty, tyaw, 0.0, 0.0)
            self.teleport_events.append((now, tx, ty, tyaw, accepted))
        if command is not None:
            robot.set_command(command[0], command[1], now)
            self.command_events.append((now, *robot.command, command[2]))

        if held != self._was_held:
            self._was_held = held
            self.hold_events.append((now, held))
        x, y, yaw, v, w = robot.next_state(dt, now)
        terrain = self.terrain
        if self.levels is not None and not held:
            x, y, what, steep = self._level_move(x, y, others)
        else:
            if terrain is not None and not held:
                x, y = terrain.surface_step(robot.x, robot.y, x, y)
            what = None if held else self.checker.colliding_with(x, y, others)
            steep = None
            if terrain is not None and not held and what is None:
                steep = terrain.blocks(robot.x, robot.y, x, y)
        if held:
            # Wheels blocked: commanded, not moving, and the encoders count nothing.
            robot.stop()
            self.odometry.update(0.0, 0.0, dt)
        elif what is None and steep is None:
            dyaw = (yaw - robot.yaw + math.pi) % (2.0 * math.pi) - math.pi
            robot.apply_state(x, y, yaw, v, w)
            self.odometry.update(v * dt, dyaw, dt)
        else:
            # Blocked (bumper, or a slope too steep to climb): the base stops where it was; the
            # wheels did not turn.
            robot.stop()
            self.odometry.update(0.0, 0.0, dt)
        return what, steep

    def _level_move(self, x: float, y: float, others: list) -> tuple:
        """A multi-level world's part of a move to ``(x, y)`` (planned on flat ground): the
        end on the level's surface, what stops it (or None) and the too-steep slope (or None);
        switches :attr:`level` (and the grids) when the move is taken onto another level."""
        levels, robot = self.levels, self.robot
        x, y = levels.surface_step(self.level, robot.x, robot.y, x, y)
        target = levels.next_level(self.level, robot.x, robot.y, x, y)
        if target is None:
            return x, y, f"edge of {self.level}", None
        if target != self.level:
            self.checker.world = levels.collision_world(target)
        what = self.checker.colliding_with(x, y, others)
        steep = None if what is not None else levels.blocks(
            self.level, target, robot.x, robot.y, x, y)
        if target != self.level:
            if what is None and steep is None:
                self.level = target
                self.collision_world = self.checker.world
                self.laser_world = levels.laser_world(target)
                self.level_events.append((self.time + self.step_size, target))
            else:
                self.checker.world = self.collision_world
        return x, y, what, steep

    def _finish_step(self, what: str | None, steep: float | None) -> None:
        """Last part of a step (after every robot and obstacle moved): the clock, collisions,
        the ground truth and the sensors that are due."""
        dt = self.step_size
        robot = self.robot
        terrain = self.terrain
        others = self._others()
        self.steps += 1
        self.time = self.steps * dt
        stamp = self.time
        collision = self.checker.record(stamp, robot.x, robot.y, what, others)
        if terrain is not None or self.levels is not None:
            collision = collision or self._slope_stop(stamp, steep)
        if collision is not None:
            self.recorder.record_collision(collision.as_dict())
            for cb in self.on_collision:
                cb(collision)
        # Half a step of tolerance: rates that are not multiples of the step stay on average.
        eps = 0.5 * dt
        if stamp + eps >= self._next_odom:
            self._next_odom = _next_due(self._next_odom, self.odom_period, stamp)
            self.recorder.record_true(stamp, robot.x, robot.y, robot.yaw)
            if terrain is not None:
                self.recorder.record_terrain(
                    stamp, terrain.height(robot.x, robot.y), terrain.slope(robot.x, robot.y)
                )
            elif self.levels is not None:
                z = self.z
                self.recorder.record_terrain(stamp, z, self.levels.slope(self.level))
                self.recorder.record_level(stamp, self.level, z, self.pitch)
            self.recorder.record_clearance(
                stamp, robot.x, robot.y, self.checker.clearance(robot.x, robot.y, others)
            )
            for cb in self.on_odometry:
                cb(stamp)
        for entry in self._periodic:
            if stamp + eps >= entry[1]:
                entry[1] = _next_due(entry[1], entry[0], stamp)
                entry[2](stamp)
        if stamp + eps >= self._next_scan:
            self._next_scan = _next_due(self._next_scan, self.scanner.period, stamp)
            ranges = self.scan_now()
            for cb in self.on_scan:
                cb(stamp, ranges)
        if self.lidar is not None and stamp + eps >= self._next_cloud:
            self._next_cloud = _next_due(self._next_cloud, self.lidar.period, stamp)
            points = self.cloud_now()
            for cb in self.on_cloud:
                cb(stamp, points)

    def _slope_stop(self, stamp: float, steep: float | None) -> Collision | None:
        """The new slope stop at ``stamp`` (``steep``: the slope that stopped the robot this
        step, None if it did not), once per stop; also counted in ``checker.collisions``."""
        robot = self.robot
        if self._slope_stop_at is not None:
            sx, sy = self._slope_stop_at
            if math.hypot(robot.x - sx, robot.y - sy) < self.SLOPE_RELEASE:
                return None
            self._slope_stop_at = None
        if steep is None:
            return None
        self._slope_stop_at = (robot.x, robot.y)
        limit = (self.terrain or self.levels).max_climb_slope_deg
        collision = Collision(
            stamp, robot.x, robot.y, f"steep slope ({math.degrees(steep):.1f} deg > {limit:g})"
        )
        self.checker.collisions.append(collision)
        return collision

    def run_for(self, duration: float) -> None:
        """Step for ``duration`` simulated seconds (tests and offline runs)."""
        for _ in range(int(round(duration / self.step_size))):
            self.step()


def move_obstacles(
    obstacles: Sequence[MovingObstacle],
    robots: Sequence[tuple[DiffDriveRobot, float]],
    now: float,
    dt: float,
) -> None:
    """Walk each obstacle for ``dt`` unless that would make it touch one of the ``robots``
    (``(robot, radius)`` pairs): it waits instead. Each obstacle first
    :meth:`~MovingObstacle.observe` s the time and every robot (in order)."""
    for obstacle in obstacles:
        for robot, _radius in robots:
            obstacle.observe(now, robot.x, robot.y)
        ox, oy = obstacle.position_after(dt)
        if all(
            math.hypot(ox - robot.x, oy - robot.y) - obstacle.radius - radius >= 0.0
            for robot, radius in robots
        ):
            obstacle.advance(dt)


def _next_due(scheduled: float, period: float, now: float) -> float:
    """Next run one period after the scheduled one; restart from ``now`` when behind."""
    nxt = scheduled + period
    return nxt if nxt > now else now + period
