"""VelocityOutput: controller_node's velocity output, one :func:`decide_velocity` per RT cycle."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace

from easynav.core.robot import RobotLimits
from easynav.core.types import SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity.cycle_input import CycleInput
from easynav.core.velocity.velocity_command import VelocityCommand
from easynav.core.velocity.velocity_decision import decide_velocity
from easynav.core.velocity.velocity_rules import ZERO, axis_bounds, check_limits, ramp
from easynav.core.velocity.velocity_source import VelocitySource
from easynav.core.velocity.velocity_state import VelocityState


class VelocityOutput:
    """controller_node's single velocity output: the one place a command leaves EasyNav.

    Holds the settings (robot limits, ``cmd_timeout``, ``keepalive_period``, ``max_dt``) and
    the :class:`VelocityState` between cycles; every RT cycle, after the controller and the
    recovery system ran, the node calls :meth:`cycle` with what they proposed, which builds one
    :class:`CycleInput` and calls :func:`decide_velocity` once; the node publishes ``twist``
    when ``publish`` is True. The rules, in order (``README.md``): refusal of a bad input, dt,
    protective stop, limits in force, new controller commands only, NaN/inf refusal, mux
    (protective stop > motion inhibited > OVERRIDE > TAKEOVER > pause > CONTROLLER),
    ``cmd_timeout``, output (exact zero in a protective stop, a fresh OVERRIDE at once and
    clamped, otherwise the acceleration ramp), publication (on changes or when the keepalive is
    due; before the first publication the robot is taken to be at rest, so a first zero is not
    published), ``diagnostics.cmd_vel``.

    **dt** of the ramp is the node-clock time since the previous :meth:`cycle` (or since the
    end of :meth:`brake_sequence`): 0 on the first cycle after construction or :meth:`reset`
    (nothing moves before a time reference exists), 0 when the clock did not advance or jumped
    back (the output holds; a protective stop still zeroes it), and at most ``max_dt`` (a
    stalled cycle or a forward jump of simulated time must not allow a step change). Using a
    smaller dt than the real elapsed time only ramps more gently, never harder than the limits.

    **Limits in force**: the robot limits given to the constructor or :meth:`set_limits`, cut
    down to the safely limited speed when ``safety`` says ``speed_limited``, then scaled by the
    speed zone passed to :meth:`cycle`. :attr:`limits_in_force` is what the last cycle enforced.

    Thread contract: :meth:`cycle` and :meth:`set_limits` are called from the RT thread only;
    :meth:`brake_sequence` and :meth:`reset` from the lifecycle (configure/deactivate/shutdown)
    thread while the RT loop does not run; :meth:`set_cmd_timeout` from the parameter thread
    (one float assignment, read by the next cycle). Not locked.
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
        self.set_cmd_timeout(cmd_timeout)
        check_limits(limits)
        self._limits = limits
        self._limits_in_force = limits
        self._state = VelocityState()

    # -- queries -----------------------------------------------------------------------------
    @property
    def robot_limits(self) -> RobotLimits:
        """The robot limits set (before the safety cut and the speed zone)."""
        return self._limits

    @property
    def limits_in_force(self) -> RobotLimits:
        """The limits the last cycle enforced (cut down by a safely limited speed and the speed
        zone); the robot limits before any cycle or after :meth:`set_limits`."""
        return self._limits_in_force

    @property
    def state(self) -> VelocityState:
        """The decision's state after the last cycle (frozen)."""
        return self._state

    @property
    def current(self) -> Twist:
        """The last command output (a new object)."""
        return Twist(*self._state.output)

    @property
    def ramp_start(self) -> float | None:
        """Node-clock time of the first :meth:`cycle` since construction or :meth:`reset` (None
        before it): the output is at rest then, and no command after it is further from zero
        than the acceleration limits allow over the time since.
        """
        return self._state.ramp_start

    @property
    def cmd_timeout(self) -> float:
        """The command timeout in seconds (0: off)."""
        return self._cmd_timeout

    def set_cmd_timeout(self, cmd_timeout: float) -> None:
        """A new command timeout (a runtime parameter change), used from the next cycle.

        Raises ``ValueError`` for a negative or non-finite value."""
        if not (math.isfinite(cmd_timeout) and cmd_timeout >= 0.0):
            raise ValueError(f"cmd_timeout = {cmd_timeout} must be finite and >= 0 (0: off)")
        self._cmd_timeout = float(cmd_timeout)

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
        speed_zone: float | None = None,
    ) -> VelocityCommand:
        """Compute this RT cycle's command: one :func:`decide_velocity`. RT thread.

        ``now``: node clock (s). ``controller_cmd``: NavState ``cmd_vel`` as it is this cycle
        (None when absent; the decision tells whether it is new). ``takeover``/``override``:
        the recovery system's proposals of this cycle, or None. ``paused``: NavState
        ``navigation_paused``. ``safety``: NavState ``safety_status`` (None when the safety
        channel's state is not read, i.e. ``safety.status.timeout`` is 0); an invalid state is
        a protective stop. ``motion_inhibited``: the safety supervisor's inhibition (old pose
        in safety mode). ``speed_zone``: NavState ``speed_limit`` (None: no zone).
        Raises as :func:`decide_velocity` does; the state is then unchanged.
        """
        decision = decide_velocity(
            CycleInput(
                now,
                controller_cmd,
                takeover,
                override,
                paused,
                safety,
                motion_inhibited,
                self._limits,
                speed_zone,
                self._cmd_timeout,
                self.keepalive_period,
                self.max_dt,
            ),
            self._state,
        )
        self._state = decision.state
        self._limits_in_force = decision.limits
        diagnostics = [decision.diagnostic] if decision.diagnostic is not None else []
        return VelocityCommand(
            decision.command, decision.publish, diagnostics, decision.source.value,
            decision.reason,
        )

    def set_limits(self, limits: RobotLimits) -> None:
        """Set the robot limits (before any safety cut or speed zone). ``ValueError`` if invalid.

        RT thread (between cycles) or lifecycle thread while the RT loop does not run.
        """
        check_limits(limits)
        self._limits = limits
        self._limits_in_force = limits

    # -- lifecycle ---------------------------------------------------------------------------
    def brake_sequence(self, now: float, dt: float) -> Iterator[Twist]:
        """The ramp from the current command to an exact zero, one Twist per ``dt`` seconds.

        For deactivation and shutdown: the node publishes each Twist and waits ``dt`` before
        asking for the next one. Each step is within the deceleration limits of the last
        cycle's limits in force, the last one is an exact zero (a single zero when already at
        rest). Afterwards the kept target is zero (source BRAKE), and the next :meth:`cycle`
        counts its dt from the end of the ramp.
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
        self._state = self._state.at_rest()

    # -- internals ---------------------------------------------------------------------------
    def _brake(self, now: float, dt: float) -> Iterator[Twist]:
        bounds = axis_bounds(self._limits_in_force)
        t = now
        while True:
            state = self._state
            output = ramp(state.output, ZERO, dt, bounds)
            self._state = replace(
                state,
                output=output,
                target=ZERO,
                source=VelocitySource.BRAKE,
                last_now=t,
                last_published=output,
                last_publish_time=t,
            )
            yield Twist(*output)
            if output == ZERO:
                return
            t += dt
