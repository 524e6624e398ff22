"""GoalClientState: the states of a GoalManagerClient."""

from __future__ import annotations

from enum import Enum


class GoalClientState(Enum):
    """Where a client's navigation stands (see :class:`GoalManagerClient` for the machine)."""

    IDLE = "IDLE"
    SENT_GOAL = "SENT_GOAL"
    SENT_PREEMPT = "SENT_PREEMPT"
    ACCEPTED_AND_NAVIGATING = "ACCEPTED_AND_NAVIGATING"
    NAVIGATION_FINISHED = "NAVIGATION_FINISHED"
    NAVIGATION_REJECTED = "NAVIGATION_REJECTED"
    NAVIGATION_FAILED = "NAVIGATION_FAILED"
    NAVIGATION_CANCELLED = "NAVIGATION_CANCELLED"
    ERROR = "ERROR"

    @property
    def is_terminal(self) -> bool:
        """True for the end states, which only :meth:`GoalManagerClient.reset` leaves."""
        return self in _TERMINAL

    @property
    def is_navigating(self) -> bool:
        """True while a goal is sent or being followed (a CANCEL makes sense)."""
        return self in _IN_PROGRESS


_TERMINAL = frozenset(
    {
        GoalClientState.NAVIGATION_FINISHED,
        GoalClientState.NAVIGATION_REJECTED,
        GoalClientState.NAVIGATION_FAILED,
        GoalClientState.NAVIGATION_CANCELLED,
        GoalClientState.ERROR,
    }
)
_IN_PROGRESS = frozenset(
    {
        GoalClientState.SENT_GOAL,
        GoalClientState.SENT_PREEMPT,
        GoalClientState.ACCEPTED_AND_NAVIGATING,
    }
)
