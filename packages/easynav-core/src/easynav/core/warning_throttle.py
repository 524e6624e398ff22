"""WarningThrottle: at most one warning per key and period, with the count of those skipped."""

from __future__ import annotations

import threading
import time
from typing import Any


class WarningThrottle:
    """Logs ``text`` for ``key`` at most once every ``period`` seconds (monotonic clock).

    A broken sensor at 30 Hz must be reported, not flood the log: the first warning goes out at
    once, later ones for the same key once per period, saying how many were held back.

    Thread contract: locked; callable from any thread.
    """

    def __init__(self, period: float = 5.0) -> None:
        self.period = period
        self._lock = threading.Lock()
        self._last: dict[Any, float] = {}
        self._held: dict[Any, int] = {}

    def warn(self, logger: Any, key: Any, text: str) -> bool:
        """Log ``text`` unless ``key`` was logged less than a period ago; True when logged."""
        now = time.monotonic()
        with self._lock:
            last = self._last.get(key)
            if last is not None and now - last < self.period:
                self._held[key] = self._held.get(key, 0) + 1
                return False
            held = self._held.pop(key, 0)
            self._last[key] = now
        if held:
            text = f"{text} ({held} similar warnings in the last {self.period:g} s not shown)"
        logger.warning(text)
        return True

    def reset(self) -> None:
        """Forget every key (the next warning of each goes out at once)."""
        with self._lock:
            self._last.clear()
            self._held.clear()
