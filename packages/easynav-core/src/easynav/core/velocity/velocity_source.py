"""VelocitySource: who decided the velocity command of a cycle."""

from __future__ import annotations

from enum import StrEnum


class VelocitySource(StrEnum):
    """The sources of the velocity mux, plus the guard's and the idle states.

    Priority, highest first (REFERENCE.md §6): PROTECTIVE_STOP > MOTION_INHIBITED > OVERRIDE >
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
