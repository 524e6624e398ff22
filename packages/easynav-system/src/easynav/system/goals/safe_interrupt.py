"""Ctrl-C noticed between two executor waits instead of inside rclpy.

Python's default SIGINT handler raises ``KeyboardInterrupt`` at whatever bytecode the main thread
is executing. Inside ``Executor.spin_once`` that can be between rclpy marking a subscription as
taken and running its task: the subscription then never enters the wait set again, and a
command that goes on to cancel its goal never hears the goal manager's answer (seen on a loaded
CI machine: the goal was cancelled, the command said it was not confirmed). So the handler here
only counts the presses, and the command's own loops turn a press into ``KeyboardInterrupt`` at a
point where no rclpy call is in flight.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType, TracebackType


class SafeInterrupt:
    """A context manager counting SIGINTs while it is entered (in the main thread only).

    Outside the main thread Python delivers no SIGINT, so entering it there changes nothing and
    :meth:`check` never raises. The previous handler is restored on exit.
    Thread contract: enter, check and exit from one thread; the handler runs in the main thread.
    """

    def __init__(self) -> None:
        self._presses = 0
        self._previous = None
        self._installed = False

    @property
    def presses(self) -> int:
        """How many times Ctrl-C was pressed since entering."""
        return self._presses

    def __enter__(self) -> SafeInterrupt:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._on_sigint)
            self._installed = True
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if self._installed:
            signal.signal(signal.SIGINT, self._previous)
            self._installed = False

    def check(self, seen: int = 0) -> None:
        """Raise ``KeyboardInterrupt`` when Ctrl-C was pressed more than ``seen`` times."""
        if self._presses > seen:
            raise KeyboardInterrupt

    def _on_sigint(self, signum: int, frame: FrameType | None) -> None:
        self._presses += 1
