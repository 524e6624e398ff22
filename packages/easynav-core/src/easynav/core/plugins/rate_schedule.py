"""RateSchedule: when a component with a frequency is due to run."""

from __future__ import annotations


class RateSchedule:
    """Drift-free schedule of a component at ``freq`` Hz on a caller-provided clock (seconds).

    - Due when at least one period has passed since the last *scheduled* time; the next run is
      scheduled one period after the previous scheduled time, so a cycle that comes a little late
      does not cost a run (30 Hz checked at 50 Hz gives 30 runs/s, gaps of 20 and 40 ms).
    - More than one period behind (e.g. the cycle stalled): it runs once and the schedule restarts
      from then, without a burst of catch-up runs.
    - A triggered run (``restart``) restarts the schedule.

    Thread contract: owned by the one loop that runs the component; not locked.
    """

    __slots__ = ("period", "_scheduled")

    def __init__(self, freq: float) -> None:
        self.period = 1.0 / freq
        self._scheduled: float | None = None

    def reset(self) -> None:
        """Forget the schedule: the next check is due at once."""
        self._scheduled = None

    def is_due(self, now: float) -> bool:
        """True (and advances the schedule) when the component must run at ``now``."""
        scheduled = self._scheduled
        if scheduled is None:
            self._scheduled = now
            return True
        elapsed = now - scheduled
        if elapsed < 0.0:  # the clock went back (simulation restarted): restart from now
            self._scheduled = now
            return True
        if elapsed < self.period - 1e-9:
            return False
        if elapsed >= 2.0 * self.period:  # more than one period behind: no catch-up burst
            self._scheduled = now
        else:
            self._scheduled = scheduled + self.period
        return True

    def restart(self, now: float) -> None:
        """A triggered run happened at ``now``: the next one is one period later."""
        self._scheduled = now
