"""Simulation: the fixed-step engine that moves the robot and produces its sensor data."""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence

import numpy as np

from easynav.playground.sim.collision import Collision
from easynav.playground.sim.collision_checker import CollisionChecker
from easynav.playground.sim.diff_drive_robot import DiffDriveRobot
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.sim.laser_scanner import LaserScanner
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.wheel_odometry import WheelOdometry
from easynav.playground.sim.world import World

ScanCallback = Callable[[float, np.ndarray], None]
StampCallback = Callable[[float], None]
CollisionCallback = Callable[[Collision], None]


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

    The laser is mounted at ``laser_offset`` ``(x, y, yaw)`` in the robot frame.

    Thread contract: :meth:`step` and the callbacks run in one thread (the simulation loop);
    :meth:`set_command` and :meth:`set_held` may be called from any thread (they only store
    under a lock).

    Raises:
        ValueError: a step or rate not finite and > 0, or a start pose in collision.
    """

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
    ) -> None:
        for name, value in (("step", step), ("odom_rate", odom_rate)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"Simulation: {name} must be finite and > 0, got {value}")
        self.world = world
        self.robot = robot
        self.scanner = scanner
        self.odometry = odometry
        self.obstacles = list(obstacles)
        self.checker = CollisionChecker(world, robot_radius)
        self.step_size = float(step)
        self.odom_period = 1.0 / float(odom_rate)
        self.laser_offset = tuple(float(v) for v in laser_offset)
        self.recorder = recorder if recorder is not None else GroundTruthRecorder()
        self.time = 0.0
        self.steps = 0
        self.on_scan: list[ScanCallback] = []
        self.on_odometry: list[StampCallback] = []
        self.on_collision: list[CollisionCallback] = []
        self._command_lock = threading.Lock()
        self._pending_command: tuple[float, float] | None = None
        self._held = False
        self._was_held = False
        self.hold_events: list[tuple[float, bool]] = []
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
    def set_command(self, v: float, w: float) -> None:
        """Queue a velocity command; the next step applies it.

        Raises:
            ValueError: ``v`` or ``w`` is NaN or infinite (nothing is queued).
        """
        if not (math.isfinite(v) and math.isfinite(w)):
            raise ValueError(f"Simulation: non-finite velocity command v={v}, w={w}")
        with self._command_lock:
            self._pending_command = (float(v), float(w))
            self.commands_received += 1

    def set_held(self, held: bool) -> None:
        """Hold the robot in place (True) or release it (False) from the next step on."""
        with self._command_lock:
            self._held = bool(held)

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
    def laser_pose(self) -> tuple[float, float, float]:
        """World pose of the laser ``(x, y, yaw)``."""
        r = self.robot
        ox, oy, oyaw = self.laser_offset
        c, s = math.cos(r.yaw), math.sin(r.yaw)
        return (r.x + c * ox - s * oy, r.y + s * ox + c * oy, r.yaw + oyaw)

    def scan_now(self) -> np.ndarray:
        """Take a scan from the current pose (no scheduling, no callbacks)."""
        return self.scanner.scan(self.world, *self.laser_pose(), self.obstacles)

    # ------------------------------------------------------------------ stepping
    def step(self) -> None:
        """Advance one fixed step (see the class documentation)."""
        dt = self.step_size
        now = self.time
        with self._command_lock:
            command, self._pending_command = self._pending_command, None
            held = self._held
        robot = self.robot
        if command is not None:
            robot.set_command(command[0], command[1], now)

        if held != self._was_held:
            self._was_held = held
            self.hold_events.append((now, held))
        x, y, yaw, v, w = robot.next_state(dt, now)
        what = None if held else self.checker.colliding_with(x, y, self.obstacles)
        if held:
            # Wheels blocked: commanded, not moving, and the encoders count nothing.
            robot.stop()
            self.odometry.update(0.0, 0.0, dt)
        elif what is None:
            dyaw = (yaw - robot.yaw + math.pi) % (2.0 * math.pi) - math.pi
            robot.apply_state(x, y, yaw, v, w)
            self.odometry.update(v * dt, dyaw, dt)
        else:
            # Blocked (bumper): the base stops where it was; the wheels did not turn.
            robot.stop()
            self.odometry.update(0.0, 0.0, dt)
        for obstacle in self.obstacles:
            obstacle.observe(now, robot.x, robot.y)
            ox, oy = obstacle.position_after(dt)
            gap = (
                math.hypot(ox - robot.x, oy - robot.y) - obstacle.radius - self.checker.robot_radius
            )
            if gap >= 0.0:
                obstacle.advance(dt)

        self.steps += 1
        self.time = self.steps * dt
        stamp = self.time
        collision = self.checker.record(stamp, robot.x, robot.y, what, self.obstacles)
        if collision is not None:
            self.recorder.record_collision(collision.as_dict())
            for cb in self.on_collision:
                cb(collision)
        # Half a step of tolerance: rates that are not multiples of the step stay on average.
        eps = 0.5 * dt
        if stamp + eps >= self._next_odom:
            self._next_odom = _next_due(self._next_odom, self.odom_period, stamp)
            self.recorder.record_true(stamp, robot.x, robot.y, robot.yaw)
            self.recorder.record_clearance(
                stamp, robot.x, robot.y, self.checker.clearance(robot.x, robot.y, self.obstacles)
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

    def run_for(self, duration: float) -> None:
        """Step for ``duration`` simulated seconds (tests and offline runs)."""
        for _ in range(int(round(duration / self.step_size))):
            self.step()


def _next_due(scheduled: float, period: float, now: float) -> float:
    """Next run one period after the scheduled one; restart from ``now`` when behind."""
    nxt = scheduled + period
    return nxt if nxt > now else now + period
