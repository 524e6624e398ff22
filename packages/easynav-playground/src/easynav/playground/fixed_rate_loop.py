"""FixedRateLoop: call a function at a fixed wall-clock period in its own thread."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable


class FixedRateLoop:
    """Runs ``tick()`` every ``period`` wall seconds with absolute deadlines (no drift).

    Deadlines advance by exactly one period per tick, so a late tick is followed by shorter
    sleeps until the loop is back on schedule. When it falls more than ``max_lag`` seconds
    behind (the machine cannot keep up) the schedule restarts from now instead of bursting
    through the backlog; :attr:`restarts` counts those.

    Thread contract: :meth:`start` and :meth:`stop` from the owning thread; ``tick`` runs in
    the loop's thread. An exception in ``tick`` stops the loop and is kept in :attr:`error`
    (re-raised by :meth:`stop`).

    Raises:
        ValueError: a period or lag not finite and > 0.
    """

    def __init__(
        self, period: float, tick: Callable[[], None], max_lag: float = 0.1, name: str = "loop"
    ) -> None:
        if not (period > 0.0 and period < float("inf")):
            raise ValueError(f"FixedRateLoop: period must be finite and > 0, got {period}")
        if not (max_lag > 0.0 and max_lag < float("inf")):
            raise ValueError(f"FixedRateLoop: max_lag must be finite and > 0, got {max_lag}")
        self.period = float(period)
        self.max_lag = float(max_lag)
        self._tick = tick
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self.ticks = 0
        self.restarts = 0
        self.error: BaseException | None = None
        self._started_at = 0.0
        self._stopped_at: float | None = None

    def start(self) -> None:
        """Start the loop thread."""
        self._started_at = time.monotonic()
        self._thread.start()

    @property
    def running(self) -> bool:
        """True while the loop thread is alive."""
        return self._thread.is_alive()

    def elapsed(self) -> float:
        """Wall seconds since :meth:`start` (until :meth:`stop`)."""
        end = self._stopped_at if self._stopped_at is not None else time.monotonic()
        return end - self._started_at if self._started_at else 0.0

    def stop(self, timeout: float = 5.0) -> None:
        """Stop and join the loop thread.

        Raises:
            RuntimeError: the thread did not finish within ``timeout``.
            BaseException: the exception that stopped ``tick``, if any.
        """
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout)
            if self._thread.is_alive():
                raise RuntimeError(f"{self._thread.name}: did not stop within {timeout} s")
        self._stopped_at = time.monotonic()
        if self.error is not None:
            raise self.error

    def _run(self) -> None:
        deadline = time.monotonic()
        try:
            while not self._stop.is_set():
                self._tick()
                self.ticks += 1
                deadline += self.period
                delay = deadline - time.monotonic()
                if delay > 0.0:
                    self._stop.wait(delay)
                elif -delay > self.max_lag:
                    deadline = time.monotonic()
                    self.restarts += 1
        except BaseException as err:  # kept for stop(); the loop cannot continue after it
            self.error = err
