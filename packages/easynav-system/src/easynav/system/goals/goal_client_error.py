"""GoalClientError: a GoalManagerClient command that its state does not allow."""

from __future__ import annotations


class GoalClientError(RuntimeError):
    """Raised by :class:`GoalManagerClient` for a command its current state does not allow
    (e.g. sending goals after the navigation ended without ``reset()``); the message names the
    state and what to do.
    """
