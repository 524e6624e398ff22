"""VelocityOutput: mux → guard → smoother → publication decision, once per RT cycle."""

from __future__ import annotations

import math
from collections.abc import Iterator

from easynav.core.robot import RobotLimits
from easynav.core.types import SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity.command_guard import CommandGuard
from easynav.core.velocity.velocity_command import VelocityCommand
from easynav.core.velocity.velocity_mux import VelocityMux
from easynav.core.velocity.velocity_smoother import VelocitySmoother
from easynav.core.velocity.velocity_source import VelocitySource

_ZERO = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class VelocityOutput:
    """controller_node's single velocity output (seed-design.txt "Velocity Output").

    Every RT cycle, after the controller and the recovery system ran, the node calls
    :meth:`cycle` with what they proposed and publishes ``twist`` when ``publish`` is True:

    1. the :class:`CommandGuard` tells whether NavState ``cmd_vel`` holds a new controller
       command (stamp or value changed);
    2. the :class:`VelocityMux` selects: protective stop > motion inhibited > OVERRIDE >
       TAKEOVER > pause > CONTROLLER, discarding non-finite proposals and keeping the last
       target when nobody proposes;
    3. the guard applies ``cmd_timeout`` (a kept non-zero target becomes zero) and reports
       ``diagnostics.cmd_vel``;
    4. the :class:`VelocitySmoother` moves the output towards the target within the limits in
       force; a protective stop outputs zero at once (the safety channel is already stopping
       the robot; afterwards the robot restarts from zero), an OVERRIDE is output at once
       (clamped to the velocity limits) and the smoother continues from it;
    5. publication: when the value changed since the last publication or, with
       ``keepalive_period`` > 0, when that long passed since it (node clock; a backwards jump
       makes it due). At rest with no keepalive nothing is republished. Before the first
       publication the robot is taken to be at rest (zero), so a first zero is not published.

    **dt** of the smoother is the node-clock time since the previous :meth:`cycle` (or since
    the end of :meth:`brake_sequence`): 0 on the first cycle after construction or
    :meth:`reset` (nothing moves before a time reference exists), 0 when the clock did not
    advance or jumped back (the output holds; a protective stop still zeroes it), and at most
    ``max_dt`` (a stalled cycle or a forward jump of simulated time must not allow a step
    change). Using a smaller dt than the real elapsed time only ramps more gently, never
    harder than the limits.

    **Limits in force**: those given to the constructor or :meth:`set_limits`, cut down to
    the safely limited speed when ``safety`` says ``speed_limited`` (so the node may pass
    either the configured ``robot_limits`` or limits it already cut down; cutting twice by the
    same speed changes nothing). :attr:`limits_in_force` is what controllers must see through
    ``get_robot_limits()``.

    Thread contract: :meth:`cycle` and :meth:`set_limits` are called from the RT thread only;
    :meth:`brake_sequence` and :meth:`reset` from the lifecycle (configure/deactivate/shutdown)
    thread while the RT loop does not run. Not locked.
    Exceptions: ``ValueError`` for invalid limits, a negative/non-finite ``cmd_timeout``,
    ``keepalive_period`` or ``max_dt``, a non-finite ``now`` or a non-positive ``dt``.
    """

    def __init__(
        self,
        limits: RobotLimits,
        cmd_timeout: float,
        keepalive_period: float,
        max_dt: float = 0.1,
    ) -> None:
        if not (math.isfinite(keepalive_period) and keepalive_period >= 0.0):
            raise ValueError(
                f"cmd_vel_keepalive_period = {keepalive_period} must be finite and >= 0 (0: off)"
            )
        if not (math.isfinite(max_dt) and max_dt > 0.0):
            raise ValueError(f"max_dt = {max_dt} must be finite and > 0")
        self.keepalive_period = float(keepalive_period)
        self.max_dt = float(max_dt)
        self._guard = CommandGuard(cmd_timeout)
        self._mux = VelocityMux()
        self._smoother = VelocitySmoother(limits)
        self._base_limits = limits
        self._cut: tuple[float, float] | None = None
        self._last_now: float | None = None
        self._ramp_start: float | None = None
        self._last_published = _ZERO
        self._last_publish_time: float | None = None

    # -- queries -----------------------------------------------------------------------------
    @property
    def limits_in_force(self) -> RobotLimits:
        """The limits the smoother enforces now (cut down by a safely limited speed)."""
        return self._smoother.limits

    @property
    def current(self) -> Twist:
        """The last command output (a new object)."""
        return self._smoother.current

    @property
    def ramp_start(self) -> float | None:
        """Node-clock time of the first :meth:`cycle` since construction or :meth:`reset` (None
        before it): the output is at rest then, and no command after it is further from zero
        than the acceleration limits allow over the time since.
        """
        return self._ramp_start

    @property
    def cmd_timeout(self) -> float:
        """The command timeout in seconds (0: off)."""
        return self._guard.cmd_timeout

    def set_cmd_timeout(self, cmd_timeout: float) -> None:
        """A new command timeout (a runtime parameter change), used from the next cycle.

        Raises ``ValueError`` for a negative or non-finite value."""
        if not (math.isfinite(cmd_timeout) and cmd_timeout >= 0.0):
            raise ValueError(f"cmd_timeout = {cmd_timeout} must be finite and >= 0 (0: off)")
        self._guard.cmd_timeout = float(cmd_timeout)

    # -- RT cycle ----------------------------------------------------------------------------
    def cycle(
        self,
        now: float,
        controller_cmd: TwistStamped | None,
        takeover: Twist | None,
        override: Twist | None,
        paused: bool,
        safety: SafetyChannelState | None,
        motion_inhibited: bool,
    ) -> VelocityCommand:
        """Compute this RT cycle's command. See the class docstring for each step.

        ``now``: node clock (s). ``controller_cmd``: NavState ``cmd_vel`` as it is this cycle
        (None when absent; the guard decides whether it is new). ``takeover``/``override``: the
        recovery system's proposals of this cycle, or None. ``paused``: NavState
        ``navigation_paused``. ``safety``: NavState ``safety_status`` (None when the safety
        channel's state is not read, i.e. ``safety.status.timeout`` is 0); an invalid state is
        a protective stop. ``motion_inhibited``: the safety supervisor's inhibition (old pose
        in safety mode).
        """
        dt = self._dt(now)
        protective_stop = False
        if safety is not None:
            protective_stop = safety.stops_robot
        if not self._apply_speed_limit(safety):
            protective_stop = True

        guard = self._guard
        controller = None
        if guard.is_new_controller_command(controller_cmd):
            controller = controller_cmd.twist
        mux = self._mux
        selection = mux.select(
            controller, takeover, override, paused, protective_stop, motion_inhibited
        )
        timed_out, diagnostic = guard.update(
            now, selection.proposed, selection.discarded, mux.target.is_zero()
        )
        if timed_out:
            mux.hold_zero(VelocitySource.TIMEOUT)

        source = mux.source
        if source is VelocitySource.PROTECTIVE_STOP:
            twist = self._smoother.stop_now()
        elif source is VelocitySource.OVERRIDE and selection.fresh:
            twist = self._smoother.jump_to(mux.target)
        else:
            twist = self._smoother.step(mux.target, dt)

        publish = self._should_publish(now, twist)
        return VelocityCommand(
            twist, publish, [diagnostic] if diagnostic is not None else [], source.value
        )

    def set_limits(self, limits: RobotLimits) -> None:
        """Set the limits in force (before any safely limited speed). ``ValueError`` if invalid.

        RT thread (e.g. each cycle with limits cut down by the safety channel) or lifecycle
        thread while the RT loop does not run.
        """
        self._base_limits = limits
        self._cut = None
        self._smoother.set_limits(limits)

    # -- lifecycle ---------------------------------------------------------------------------
    def brake_sequence(self, now: float, dt: float) -> Iterator[Twist]:
        """The ramp from the current command to an exact zero, one Twist per ``dt`` seconds.

        For deactivation and shutdown: the node publishes each Twist and waits ``dt`` before
        asking for the next one. Each step is within the deceleration limits, the last one is
        an exact zero (a single zero when already at rest). Afterwards the kept target is zero
        (source BRAKE), and the next :meth:`cycle` counts its dt from the end of the ramp.
        Raises ``ValueError`` for a non-positive or non-finite ``dt`` or a non-finite ``now``.
        """
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"dt = {dt} must be finite and > 0")
        if not math.isfinite(now):
            raise ValueError(f"now = {now} is not finite")
        return self._brake(now, dt)

    def reset(self) -> None:
        """Start from rest (on activation): output, target, clocks and keepalive forgotten.

        The command guard's reported problem, if any, stays until commands flow again.
        """
        self._mux.reset()
        self._smoother.reset()
        self._guard.reset()
        self._last_now = None
        self._ramp_start = None
        self._last_published = _ZERO
        self._last_publish_time = None

    # -- internals ---------------------------------------------------------------------------
    def _brake(self, now: float, dt: float) -> Iterator[Twist]:
        self._mux.hold_zero(VelocitySource.BRAKE)
        zero = Twist()
        t = now
        while True:
            twist = self._smoother.step(zero, dt)
            self._last_published = twist.as_tuple()
            self._last_publish_time = t
            self._last_now = t
            done = twist.is_zero()
            yield twist
            if done:
                return
            t += dt

    def _dt(self, now: float) -> float:
        if not math.isfinite(now):
            raise ValueError(f"now = {now} is not finite")
        last = self._last_now
        self._last_now = now
        if last is None:
            self._ramp_start = now
            return 0.0
        dt = now - last
        if dt <= 0.0:
            return 0.0
        return dt if dt < self.max_dt else self.max_dt

    def _apply_speed_limit(self, safety: SafetyChannelState | None) -> bool:
        """Cut the limits down to a safely limited speed; False when its limits are unusable.

        SafetyChannelMonitor never marks a state with a negative or NaN limit valid; a state
        built elsewhere might, and is then treated as the spec treats an invalid status: as
        a protective stop.
        """
        cut = (
            (safety.max_linear_vel, safety.max_angular_vel)
            if safety is not None and safety.valid and safety.speed_limited
            else None
        )
        if cut is not None and not (cut[0] >= 0.0 and cut[1] >= 0.0):
            return False
        if cut == self._cut:
            return True
        self._cut = cut
        if cut is None:
            self._smoother.set_limits(self._base_limits)
        else:
            self._smoother.set_limits(self._base_limits.cut_down(cut[0], cut[1]))
        return True

    def _should_publish(self, now: float, twist: Twist) -> bool:
        value = twist.as_tuple()
        due = value != self._last_published
        if not due and self.keepalive_period > 0.0:
            last = self._last_publish_time
            due = last is None or now < last or now - last >= self.keepalive_period
        if due:
            self._last_published = value
            self._last_publish_time = now
        return due
