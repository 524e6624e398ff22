"""DiffDriveRobot: unicycle kinematics of a differential-drive base with motor limits."""

from __future__ import annotations

import math

from easynav.playground.sim.base_limits import BaseLimits


def _ramp(current: float, target: float, acc: float, decel: float, dt: float) -> float:
    """Move ``current`` toward ``target``: ``acc`` while speeding up, ``decel`` while slowing.

    Crossing zero takes the braking part first, so a reversal never exceeds either limit.
    """
    if current == target:
        return current
    if current != 0.0 and (target == 0.0 or (target > 0.0) != (current > 0.0)):
        # Slowing down toward zero (and maybe past it, then speeding up the other way).
        step = decel * dt
        if abs(current) > step:
            return current - math.copysign(step, current)
        remaining = dt - abs(current) / decel
        if target == 0.0:
            return 0.0
        return math.copysign(min(abs(target), acc * remaining), target)
    if abs(target) > abs(current):
        return current + math.copysign(min(acc * dt, abs(target) - abs(current)), target)
    return current - math.copysign(min(decel * dt, abs(current) - abs(target)), current)


class DiffDriveRobot:
    """Pose ``(x, y, yaw)`` in the world and velocities ``(v, w)`` of a differential-drive base.

    Each :meth:`step` ramps the actual velocities toward the last command within the base
    limits and integrates the unicycle model exactly (arc of constant ``v, w``) over ``dt``.
    Like a real driver it keeps executing the last command; with ``cmd_timeout > 0`` it
    brakes to zero when no command arrived for that long (a watchdog some drivers offer).

    Thread contract: not thread-safe; one thread (the simulation loop) calls every method.
    The node hands commands to that thread (see ``Simulation.set_command``).

    Raises:
        ValueError: a non-finite start pose, a negative ``cmd_timeout``, or a non-finite command.
    """

    def __init__(
        self,
        x: float = 0.0,
        y: float = 0.0,
        yaw: float = 0.0,
        limits: BaseLimits | None = None,
        cmd_timeout: float = 0.0,
    ) -> None:
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(f"DiffDriveRobot: start pose must be finite, got {(x, y, yaw)}")
        if not (math.isfinite(cmd_timeout) and cmd_timeout >= 0.0):
            raise ValueError(f"DiffDriveRobot: cmd_timeout must be >= 0, got {cmd_timeout}")
        self.x = float(x)
        self.y = float(y)
        self.yaw = float(yaw)
        self.v = 0.0
        self.w = 0.0
        self.limits = limits or BaseLimits()
        self.cmd_timeout = float(cmd_timeout)
        self._cmd_v = 0.0
        self._cmd_w = 0.0
        self._cmd_time: float | None = None

    @property
    def command(self) -> tuple[float, float]:
        """The command being executed ``(v, w)``, after clamping to the base limits."""
        return (self._cmd_v, self._cmd_w)

    def set_command(self, v: float, w: float, now: float) -> None:
        """Command linear ``v`` (m/s) and angular ``w`` (rad/s) at simulated time ``now``.

        Values beyond the base limits are clamped, as a motor controller saturates.

        Raises:
            ValueError: ``v`` or ``w`` is NaN or infinite (the command is not applied).
        """
        if not (math.isfinite(v) and math.isfinite(w)):
            raise ValueError(f"DiffDriveRobot: non-finite velocity command v={v}, w={w}")
        lim = self.limits
        self._cmd_v = min(max(v, -lim.max_linear_vel), lim.max_linear_vel)
        self._cmd_w = min(max(w, -lim.max_angular_vel), lim.max_angular_vel)
        self._cmd_time = now

    def next_state(self, dt: float, now: float) -> tuple[float, float, float, float, float]:
        """The state ``(x, y, yaw, v, w)`` after ``dt`` s, without applying it.

        ``now`` is the simulated time at the start of the step (for the command watchdog).
        """
        target_v, target_w = self._cmd_v, self._cmd_w
        if self.cmd_timeout > 0.0 and (
            self._cmd_time is None or now - self._cmd_time > self.cmd_timeout
        ):
            target_v = target_w = 0.0
        lim = self.limits
        v = _ramp(self.v, target_v, lim.max_linear_acc, lim.max_linear_decel, dt)
        w = _ramp(self.w, target_w, lim.max_angular_acc, lim.max_angular_decel, dt)
        x, y, yaw = integrate_unicycle(self.x, self.y, self.yaw, v, w, dt)
        return x, y, yaw, v, w

    def apply_state(self, x: float, y: float, yaw: float, v: float, w: float) -> None:
        """Take a state computed by :meth:`next_state` (or a blocked one after a collision)."""
        self.x, self.y, self.yaw, self.v, self.w = x, y, _wrap(yaw), v, w

    def step(self, dt: float, now: float) -> None:
        """Advance ``dt`` s with no obstacle in the way."""
        self.apply_state(*self.next_state(dt, now))

    def stop(self) -> None:
        """Zero the actual velocities (the base was blocked, e.g. a bumper hit)."""
        self.v = 0.0
        self.w = 0.0


def integrate_unicycle(
    x: float, y: float, yaw: float, v: float, w: float, dt: float
) -> tuple[float, float, float]:
    """Exact pose after driving the arc of constant ``v, w`` for ``dt`` s."""
    dyaw = w * dt
    if abs(dyaw) < 1e-9:
        return x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw), yaw
    radius = v / w
    new_yaw = yaw + dyaw
    return (
        x + radius * (math.sin(new_yaw) - math.sin(yaw)),
        y - radius * (math.cos(new_yaw) - math.cos(yaw)),
        new_yaw,
    )


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi
