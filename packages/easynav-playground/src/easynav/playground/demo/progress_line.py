"""ProgressLine: one status line, redrawn in place on a terminal, printed at times otherwise."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressLine:
    """Shows the latest status: on a TTY the line is redrawn in place (at most 10 times a
    second); on a pipe or file a line is printed every ``period`` seconds.

    Thread contract: one thread (the demo's main loop).
    """

    def __init__(self, stream: TextIO | None = None, period: float = 5.0) -> None:
        self.stream = stream or sys.stdout
        self.is_tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.period = period if not self.is_tty else 0.1
        self._last = -float("inf")
        self._width = 0

    def show(self, text: str, force: bool = False) -> None:
        """Display ``text`` if it is time to (or ``force``)."""
        now = time.monotonic()
        if not force and now - self._last < self.period:
            return
        self._last = now
        if self.is_tty:
            pad = max(self._width - len(text), 0)
            self.stream.write("\r" + text + " " * pad)
            self._width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def finish(self) -> None:
        """End the in-place line (so the next output starts on a fresh line)."""
        if self.is_tty and self._width:
            self.stream.write("\n")
            self.stream.flush()
            self._width = 0
