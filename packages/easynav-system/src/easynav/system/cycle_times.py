"""CycleTimes: how long a plugin's update (or update_rt) takes, over the last runs."""

from __future__ import annotations

import re

import numpy as np

#: The line :meth:`CycleTimes.describe` writes; tools that read EasyNav's log (the playground
#: demo's summary) parse it with :data:`DESCRIPTION_PATTERN`.
DESCRIPTION_PATTERN = re.compile(
    r"cycle time of (?P<alias>\S+) \((?P<plugin>[^)]*)\)\.(?P<method>update_rt|update): "
    r"(?P<runs>\d+) runs, median (?P<median>[\d.]+) ms, p99 (?P<p99>[\d.]+) ms, "
    r"max (?P<max>[\d.]+) ms"
)


class CycleTimes:
    """The durations of the last ``capacity`` runs (a ring of floats) and the count of all.

    Recording costs one array store: it sits on the RT path, around every plugin call. The
    statistics are computed only when asked for (:meth:`summary`), at deactivation.

    Thread contract: :meth:`record` from the loop that runs the plugin; :meth:`summary` and
    :meth:`describe` once that loop no longer runs it (deactivated), or accept a torn last
    value. No exceptions.
    """

    __slots__ = ("_ring", "_count")

    def __init__(self, capacity: int = 20_000) -> None:
        self._ring = np.zeros(capacity)
        self._count = 0

    def record(self, seconds: float) -> None:
        """One run took ``seconds``."""
        self._ring[self._count % self._ring.size] = seconds
        self._count += 1

    @property
    def count(self) -> int:
        """Runs recorded since creation (the statistics cover the last ``capacity``)."""
        return self._count

    def summary(self) -> tuple[float, float, float] | None:
        """``(median, p99, max)`` in seconds over the kept runs, None before the first."""
        if self._count == 0:
            return None
        kept = self._ring[: min(self._count, self._ring.size)]
        median, p99 = np.percentile(kept, (50.0, 99.0))
        return float(median), float(p99), float(kept.max())

    def describe(self, alias: str, plugin: str, method: str) -> str | None:
        """One log line (matching :data:`DESCRIPTION_PATTERN`), None before the first run."""
        stats = self.summary()
        if stats is None:
            return None
        median, p99, worst = (1e3 * v for v in stats)
        return (
            f"cycle time of {alias} ({plugin}).{method}: {self._count} runs, "
            f"median {median:.3f} ms, p99 {p99:.3f} ms, max {worst:.3f} ms"
        )
