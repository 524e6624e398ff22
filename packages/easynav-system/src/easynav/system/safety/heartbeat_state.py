"""HeartbeatState: when the RT cycle publishes a heartbeat; HeartbeatFields: what it contains."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class HeartbeatFields:
    """Fields of a Heartbeat message except its header (the node stamps it when publishing).

    ``sequence``: +1 per heartbeat (a gap means lost heartbeats); ``rt_status``: RT_OK,
    RT_LATE or RT_ERROR; ``late_cycles``: late RT cycles since activation; ``safety_mode``;
    ``configuration_hash``: the configuration fingerprint (SHA-256 hex).
    """

    sequence: int
    rt_status: int
    late_cycles: int
    safety_mode: bool
    configuration_hash: str


class HeartbeatState:
    """The heartbeat (``easynav_heartbeat``, with ``safety.heartbeat.period`` > 0), published
    from the RT cycle itself so that it stops when that cycle does: receivers that request a
    deadline learn that EasyNav stopped commanding.

    Each RT cycle the node calls :meth:`poll` with ``time.monotonic()``; when it returns fields,
    the node publishes a Heartbeat with them (and a header stamped now). The first poll after
    construction or :meth:`restart` is due at once; then one every ``period`` seconds on the
    monotonic clock, scheduled from the previous due time (no drift). If the cycle fell more
    than a period behind (it stalled), one heartbeat is sent and the schedule restarts from
    then: no burst of catch-up heartbeats, and the gap is visible to the receiver's deadline.
    ``sequence`` goes up by one per heartbeat and is never reset (not even by :meth:`restart`):
    a receiver sees a gap only when heartbeats were really lost. ``period`` 0 disables it.

    Thread contract: :meth:`poll` from the RT thread only; :meth:`restart` and
    :meth:`set_configuration_hash` from the lifecycle thread while the RT loop does not run.
    Exceptions: ``ValueError`` for a negative or non-finite period.
    """

    def __init__(self, period: float, safety_mode: bool, configuration_hash: str = "") -> None:
        if not (math.isfinite(period) and period >= 0.0):
            raise ValueError(f"safety.heartbeat.period = {period} must be finite and >= 0 (0: off)")
        self.period = float(period)
        self.safety_mode = bool(safety_mode)
        self.configuration_hash = configuration_hash
        self._sequence = 0
        self._next_due: float | None = None

    @property
    def enabled(self) -> bool:
        """False when ``safety.heartbeat.period`` is 0."""
        return self.period > 0.0

    @property
    def sequence(self) -> int:
        """The sequence number of the last heartbeat produced (0 before the first)."""
        return self._sequence

    def set_configuration_hash(self, configuration_hash: str) -> None:
        """The fingerprint to send (after each successful configure)."""
        self.configuration_hash = configuration_hash

    def restart(self) -> None:
        """On activation: the next poll is due at once (the sequence continues)."""
        self._next_due = None

    def is_due(self, monotonic_now: float) -> bool:
        """Whether a heartbeat is due at ``monotonic_now`` (does not advance the schedule)."""
        if not self.enabled:
            return False
        return self._next_due is None or monotonic_now >= self._next_due

    def poll(
        self, monotonic_now: float, rt_status: int, late_cycles: int
    ) -> HeartbeatFields | None:
        """The heartbeat to publish now, or None when none is due (advances the schedule)."""
        if not self.is_due(monotonic_now):
            return None
        due = self._next_due
        if due is None or monotonic_now - due >= self.period:
            self._next_due = monotonic_now + self.period
        else:
            self._next_due = due + self.period
        self._sequence += 1
        return HeartbeatFields(
            sequence=self._sequence,
            rt_status=rt_status,
            late_cycles=late_cycles,
            safety_mode=self.safety_mode,
            configuration_hash=self.configuration_hash,
        )
