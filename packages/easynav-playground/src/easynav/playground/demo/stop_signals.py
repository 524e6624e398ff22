"""StopSignals: Ctrl-C and SIGTERM noted while a demo spins, and raised where the demo checks."""

from __future__ import annotations

import signal
import threading


class StopSignals:
    """Within ``with StopSignals() as stop:``, SIGINT (Ctrl-C) and SIGTERM only set a flag;
    ``stop.check()`` raises :class:`KeyboardInterrupt` once one arrived.

    Why: the demo spins rclpy's EventsExecutor, which calls the monitor's callbacks from C++.
    Python runs a signal's handler at the next line of Python, which is often inside such a
    callback; a KeyboardInterrupt raised there came out of ``spin_once`` as a RuntimeError
    ("Unable to convert call argument") and the demo ended with a traceback instead of
    "interrupted". Checked after each ``spin_once``, the interrupt is raised in the demo's own
    code. The previous handlers are restored on leaving. Outside the main thread (where Python
    refuses to set handlers) nothing is changed and ``check()`` never raises.

    Thread contract: enter, leave and check from the main thread.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.requested = False
        self._previous: dict[int, object] = {}

    def __enter__(self) -> StopSignals:
        if threading.current_thread() is threading.main_thread():
            for sig in self.SIGNALS:
                self._previous[sig] = signal.signal(sig, self._note)
        return self

    def __exit__(self, *exc) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()

    def _note(self, signum, frame) -> None:
        self.requested = True

    def check(self) -> None:
        """Raise KeyboardInterrupt if a stop signal arrived (once: the flag is cleared)."""
        if self.requested:
            self.requested = False
            raise KeyboardInterrupt
