"""VelocityCommand: what controller_node does with the velocity output of one RT cycle."""

from __future__ import annotations

from dataclasses import dataclass, field

from easynav.core.types import DiagnosticStatus, Twist


@dataclass(slots=True)
class VelocityCommand:
    """The result of :meth:`VelocityOutput.cycle`.

    ``twist``: the command (a new object each cycle; the node may keep it).
    ``publish``: True when the node must publish ``twist`` this cycle (its value changed since
    the last publication, or the keepalive is due). ``diagnostics``: diagnostic changes to write
    in NavState (``diagnostics.<status.name>``, i.e. ``diagnostics.cmd_vel``), usually empty.
    ``source``: the :class:`VelocitySource` value of the target in force (when no source
    proposed this cycle, the one that set the kept target). ``reason``: why this command, in
    words (:attr:`VelocityDecision.reason`).
    """

    twist: Twist
    publish: bool
    diagnostics: list[DiagnosticStatus] = field(default_factory=list)
    source: str = "none"
    reason: str = ""
