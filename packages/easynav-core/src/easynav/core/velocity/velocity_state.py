"""VelocityState: what the velocity decision carries from one RT cycle to the next, frozen."""

from __future__ import annotations

from dataclasses import dataclass

from easynav.core.velocity.velocity_rules import ZERO, GuardReport, Vec6
from easynav.core.velocity.velocity_source import VelocitySource


@dataclass(frozen=True, slots=True)
class VelocityState:
    """The decision's memory between cycles; ``VelocityState()`` is "at rest, nothing seen".

    Each :func:`~easynav.core.velocity.velocity_decision.decide_velocity` returns the next one
    in :attr:`VelocityDecision.state`; pass it to the next cycle's decision.

    ``output``: the last command decided ``(vx, vy, vz, wx, wy, wz)`` (the ramp continues from
    it). ``target`` / ``source``: the mux's kept target and who set it (kept while no source
    proposes). ``last_now``: node-clock time of the previous cycle (None: no time reference
    yet, the next dt is 0). ``ramp_start``: time of the first cycle since rest.
    ``last_stamp`` / ``last_values``: the last controller command seen (new-command test).
    ``last_proposal_time``, ``timeout_active``, ``discarded``, ``reported``: the command
    guard's ``cmd_timeout`` count and ``diagnostics.cmd_vel`` memory. ``last_published`` /
    ``last_publish_time``: the last publication (before any: zero, None).
    """

    output: Vec6 = ZERO
    target: Vec6 = ZERO
    source: VelocitySource = VelocitySource.NONE
    last_now: float | None = None
    ramp_start: float | None = None
    last_stamp: float | None = None
    last_values: tuple[float, ...] = ()
    last_proposal_time: float | None = None
    timeout_active: bool = False
    discarded: tuple[VelocitySource, ...] = ()
    reported: GuardReport | None = None
    last_published: Vec6 = ZERO
    last_publish_time: float | None = None

    def at_rest(self) -> VelocityState:
        """Start from rest (activation): everything forgotten but the guard's reported problem,
        which stays until commands flow again."""
        return VelocityState(
            timeout_active=self.timeout_active,
            discarded=self.discarded,
            reported=self.reported,
        )
