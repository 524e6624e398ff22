"""VelocitySource: who decided the velocity command of a cycle."""

from __future__ import annotations

from enum import Enum


class VelocitySource(str, Enum):
    """The sources of the velocity mux, plus the guard's and the idle states.

    Priority, highest first: PROTECTIVE_STOP > MOTION_INHIBITED > OVERRIDE >
    TAKEOVER > PAUSE > CONTROLLER. ``TIMEOUT`` is the zero target the command guard sets when no
    source proposed a new command for ``cmd_timeout``; ``NONE`` is the state before any proposal.
    ``BRAKE`` is the deactivation/shutdown ramp (:meth:`VelocityOutput.brake_sequence`).
    Values are the lower-case names, e.g. ``"controller"``, so they read well in logs.
    """

    PROTECTIVE_STOP = "protective_stop"
    MOTION_INHIBITED = "motion_inhibited"
    OVERRIDE = "override"
    TAKEOVER = "takeover"
    PAUSE = "pause"
    CONTROLLER = "controller"
    TIMEOUT = "timeout"
    NONE = "none"
    BRAKE = "brake"

    # StrEnum's behaviour (Python >= 3.11) on 3.10 too: str() and f-strings give the value.
    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)
