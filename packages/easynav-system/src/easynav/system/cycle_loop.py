"""CycleLoop: a thread that runs a cycle at a fixed frequency with absolute deadlines."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from rclpy.executors import Executor, ExternalShutdownException

from easynav.system.safety.realtime import set_thread_realtime

#: Before a deadline, the loop stops waiting in the executor this long ahead and sleeps instead.
WAIT_GUARD = 0.001  # s


class CycleLoop(threading.Thread):
    """Runs ``cycle(triggered)`` every ``1/freq`` s on the monotonic clock, in its own thread.

    Deadlines are absolute (``start + k·period``): the loop does not drift. A loop that falls
    more than one period behind restarts its schedule from now (no burst of catch-up cycles).
    Between cycles it spins its executor until ``wait_guard`` (``WAIT_GUARD``, at most a fifth
    of the period) before the next deadline, so ROS callbacks are served as they arrive, then
    sleeps to the deadline (a sleep wakes up on time more precisely than the executor's wait);
    after a cycle that overran, it still spins for at most ``spin_time`` so callbacks are not
    starved. With ``wake`` (the RT loop), a callback that brings new sensor data runs a
    triggered cycle at once, keeping perception-to-action latency low (data arriving in the last
    ``wait_guard`` before a deadline is served right after that deadline's cycle).

    With ``realtime`` the thread asks for SCHED_FIFO ``priority`` (a warning, and normal priority,
    where it is not permitted). ``on_realtime_result(ok, message)`` reports the outcome.

    Thread contract: ``start``/``stop`` from the owner's thread; ``cycle`` and ``wake`` run in the
    loop's thread. Exceptions from ``cycle`` are logged through ``on_error`` and the loop goes on.
    """

    def __init__(
        self,
        name: str,
        freq: float,
        executor: Executor,
        cycle: Callable[[bool], None],
        spin_time: float,
        wake: Callable[[], bool] | None = None,
        realtime: bool = False,
        priority: int = 80,
        on_realtime_result: Callable[[bool, str], None] | None = None,
        on_error: Callable[[BaseException], None] | None = None,
    ) -> None:
        super().__init__(name=name, daemon=True)
        self.period = 1.0 / freq
        # Never more than a fifth of the period, so a fast loop still spends most of it serving
        # callbacks.
        self.wait_guard = min(WAIT_GUARD, 0.2 * self.period)
        self.executor = executor
        self.cycle = cycle
        self.spin_time = spin_time
        self.wake = wake
        self.realtime = realtime
        self.priority = priority
        self.on_realtime_result = on_realtime_result
        self.on_error = on_error
        self._stop_event = threading.Event()
        self.cycles = 0
        self.triggered_cycles = 0

    def stop(self) -> None:
        """Ask the loop to end after its current step."""
        self._stop_event.set()

    def _become_realtime(self) -> None:
        if not self.realtime:
            return
        ok, message = set_thread_realtime(self.priority)
        if self.on_realtime_result is not None:
            self.on_realtime_result(ok, f"{self.name}: {message}")

    def _run_cycle(self, triggered: bool) -> None:
        try:
            self.cycle(triggered)
        except Exception as exc:  # a cycle must never kill the loop
            if self.on_error is not None:
                self.on_error(exc)
        self.cycles += 1
        if triggered:
            self.triggered_cycles += 1

    def _spin(self, timeout: float) -> bool:
        """Serve at most one callback; False when the executor is gone."""
        try:
            self.executor.spin_once(timeout_sec=max(0.0, timeout))
        except (ExternalShutdownException, KeyboardInterrupt):
            return False
        except Exception as exc:
            if self._stop_event.is_set():
                return False
            if self.on_error is not None:
                self.on_error(exc)
        return True

    def run(self) -> None:
        self._become_realtime()
        period = self.period
        stop = self._stop_event
        monotonic = time.monotonic
        deadline = monotonic()
        while not stop.is_set():
            now = monotonic()
            if now >= deadline:
                self._run_cycle(False)
                deadline += period
                end_of_cycle = monotonic()
                if end_of_cycle > deadline + period:  # more than one period behind: restart
                    deadline = end_of_cycle + period
                # Overran: serve pending callbacks for at most spin_time, then cycle again. The
                # executor waits for them (no polling: with the EventsExecutor a spin_once(0)
                # costs microseconds, and polling burnt the whole spin_time after each overrun).
                window_end = min(end_of_cycle + self.spin_time, deadline + period)
                while True:
                    now = monotonic()
                    if now >= window_end or now < deadline:
                        break
                    if not self._spin(window_end - now):
                        return
                    if stop.is_set():
                        return
                continue
            remaining = deadline - now
            if remaining <= self.wait_guard:
                # The executor's wait (rcl_wait) wakes up late by ~0.1 ms at p99, a plain sleep
                # by about half that (bench_rt_loop.py): the last stretch before a deadline is
                # slept, so the cycle starts on time; callbacks that arrive meanwhile are served
                # right after it.
                time.sleep(remaining)
                continue
            if not self._spin(remaining - self.wait_guard):
                return
            if self.wake is not None and self.wake():
                self._run_cycle(True)
