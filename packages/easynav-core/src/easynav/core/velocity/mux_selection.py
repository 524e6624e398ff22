"""MuxSelection: what the velocity mux decided in one cycle."""

from __future__ import annotations

from dataclasses import dataclass

from easynav.core.types import Twist
from easynav.core.velocity.velocity_source import VelocitySource


@dataclass(slots=True)
class MuxSelection:
    """The result of :meth:`VelocityMux.select`.

    ``target``: the velocity the smoother must bring the output to (a copy, owned by the mux;
    read it, do not modify it). ``source``: who set that target. ``fresh``: the target was set
    this cycle (False when no source proposed and the last target is kept). ``proposed``: a
    source that commands motion (CONTROLLER, TAKEOVER or OVERRIDE) proposed a valid command
    this cycle, selected or not; this is what the command guard's ``cmd_timeout`` watches.
    ``discarded``: the sources whose proposal was discarded this cycle for being non-finite.
    """

    target: Twist
    source: VelocitySource
    fresh: bool
    proposed: bool
    discarded: tuple[VelocitySource, ...]
