"""SafetyChannelMonitor: the certified safety channel's live state, as EasyNav applies it."""

from __future__ import annotations

import math

from easynav.core.types import DiagnosticLevel, DiagnosticStatus, SafetyChannelState

# (protective_stop, speed_limited, max_linear_vel, max_angular_vel, active_field, muting,
#  receive_monotonic)
_Status = tuple[bool, bool, float, float, str, bool, float]


class SafetyChannelMonitor:
    """The safety channel's live state (protective stop, safely limited speed), read with
    ``safety.status.timeout`` > 0 so that EasyNav does not work against the certified channel.

    system_node's subscription to ``easynav_safety_status`` calls :meth:`on_status` with the
    message fields and the reception time on the monotonic clock; each RT cycle reads
    :meth:`state` (written to NavState ``safety_status``) and :meth:`diagnostic_change`
    (written to ``diagnostics.safety_status`` when not None).

    The state is treated as a protective stop (``valid`` False, ``stops_robot`` True) when no
    status arrived yet, when the last one was received more than ``timeout`` seconds ago
    (monotonic reception time, not its header stamp), or when it is invalid: ``speed_limited``
    with a negative or NaN limit. A valid ``speed_limited`` state carries the limits (>= 0);
    otherwise the limits are +inf.

    Diagnostics (hardware_id ``system_node``, name ``safety_status``), on every change: OK (with
    the speed limit, if any), WARN during a protective stop, ERROR without a valid status; the
    values carry ``active_field`` and ``muting``.

    Thread contract: :meth:`on_status` runs in the RT callback group's thread (or any single
    thread) and only stores one tuple (an atomic reference assignment, no lock);
    :meth:`state` and :meth:`diagnostic_change` run in the RT thread. :meth:`state` returns the
    same object while nothing changes, so the RT cycle does not allocate a new one each cycle:
    treat it as read-only. Exceptions: ``ValueError`` for a non-positive or non-finite timeout.
    """

    NAME = "safety_status"
    HARDWARE_ID = "system_node"

    def __init__(self, timeout: float) -> None:
        if not (math.isfinite(timeout) and timeout > 0.0):
            raise ValueError(
                f"safety.status.timeout = {timeout} must be finite and > 0 to read the "
                "safety channel's state"
            )
        self.timeout = float(timeout)
        self._last: _Status | None = None
        self._cached_last: _Status | None = None
        self._cached_contents: tuple[object, ...] | None = None
        self._cached_fresh: bool | None = None
        self._state = SafetyChannelState()
        self._reported: tuple[object, ...] | None = None

    def on_status(
        self,
        protective_stop: bool,
        speed_limited: bool,
        max_linear_vel: float,
        max_angular_vel: float,
        active_field: str,
        muting: bool,
        receive_monotonic: float,
    ) -> None:
        """Store a received SafetyStatus (fields as in the message) and its reception time."""
        self._last = (
            bool(protective_stop),
            bool(speed_limited),
            float(max_linear_vel),
            float(max_angular_vel),
            str(active_field),
            bool(muting),
            float(receive_monotonic),
        )

    def state(self, monotonic_now: float) -> SafetyChannelState:
        """The state to apply at ``monotonic_now`` (the same object while unchanged)."""
        last = self._last
        fresh = last is not None and monotonic_now - last[6] <= self.timeout
        if last is self._cached_last and fresh == self._cached_fresh:
            return self._state  # fast path: no new status, same freshness
        # A new status (or a change of freshness): rebuild only if the contents changed.
        contents = last[:6] if last is not None else None
        self._cached_last = last
        if contents == self._cached_contents and fresh == self._cached_fresh:
            return self._state
        self._cached_contents = contents
        self._cached_fresh = fresh
        self._state = self._build(last, fresh)
        return self._state

    def diagnostic_change(self, monotonic_now: float) -> DiagnosticStatus | None:
        """``diagnostics.safety_status`` when it changed since the last one written, else None."""
        state = self.state(monotonic_now)
        if not state.valid:
            level, message = DiagnosticLevel.ERROR, state.reason
        elif state.protective_stop:
            level, message = DiagnosticLevel.WARN, "protective stop"
        elif state.speed_limited:
            level = DiagnosticLevel.OK
            message = (
                f"safely limited speed: {state.max_linear_vel:g} m/s, "
                f"{state.max_angular_vel:g} rad/s"
            )
        else:
            level, message = DiagnosticLevel.OK, "no protective stop, no speed limit"
        key = (level, message, state.active_field, state.muting)
        if key == self._reported:
            return None
        self._reported = key
        values = {"active_field": state.active_field, "muting": "true" if state.muting else "false"}
        if state.valid and state.speed_limited:
            values["max_linear_vel"] = repr(state.max_linear_vel)
            values["max_angular_vel"] = repr(state.max_angular_vel)
        return DiagnosticStatus(
            level=level,
            name=self.NAME,
            message=message,
            hardware_id=self.HARDWARE_ID,
            values=values,
        )

    def _build(self, last: _Status | None, fresh: bool) -> SafetyChannelState:
        if last is None:
            return SafetyChannelState(reason="no safety status received yet")
        stop, limited, linear, angular, field, muting, _received = last
        if not fresh:
            return SafetyChannelState(
                active_field=field,
                muting=muting,
                reason=f"no safety status for more than safety.status.timeout = {self.timeout:g} s",
            )
        if limited and not (linear >= 0.0 and angular >= 0.0):  # also catches NaN
            return SafetyChannelState(
                active_field=field,
                muting=muting,
                reason=f"invalid safety status: speed limit max_linear_vel = {linear!r}, "
                f"max_angular_vel = {angular!r} (must be >= 0)",
            )
        return SafetyChannelState(
            valid=True,
            protective_stop=stop,
            speed_limited=limited,
            max_linear_vel=linear if limited else math.inf,
            max_angular_vel=angular if limited else math.inf,
            active_field=field,
            muting=muting,
            reason="",
        )
