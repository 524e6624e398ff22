"""InjectedFaultError: the exception a Faulty plugin raises for its ``throw`` fault."""

from __future__ import annotations


class InjectedFaultError(RuntimeError):
    """Raised on purpose by a Faulty plugin whose ``fault`` is ``throw``.

    A distinct type, so a test or a log reader can tell an injected failure from a real bug.
    """
