"""EasyNavRuntime's signal handling, in this process: the handler only notes the signal."""

from __future__ import annotations

import signal
import threading

import pytest

from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def test_a_signal_handled_while_the_main_thread_holds_the_stop_events_lock_is_not_lost(
    params_file, runtime_factory
):
    """Python runs a signal handler in the main thread between two bytecodes, possibly inside
    ``Event.wait`` while that thread holds the event's lock. The handler used to set that event
    itself: the process deadlocked (one SIGTERM in ten) until a second signal killed it without
    a controlled stop."""
    runtime = runtime_factory(params_file(system_params()))
    assert runtime.start(), runtime.error
    # CPython's Event keeps its lock in the private ``_cond``: what Event.wait holds at moments.
    event_lock = runtime.requests.shutdown_event._cond

    def handler_inside_event_wait() -> None:
        with event_lock:
            runtime._on_signal(signal.SIGTERM, None)

    handler = threading.Thread(target=handler_inside_event_wait, daemon=True)
    handler.start()
    handler.join(timeout=5.0)
    assert not handler.is_alive(), "the signal handler blocked on the stop event's lock"
    assert runtime.wait(timeout=5.0)
    result = runtime.stop()
    assert (result.exit_code, result.reason) == (0, "received SIGTERM")


def test_a_signal_noted_before_anyone_waits_is_the_stop_reason(params_file, runtime_factory):
    runtime = runtime_factory(params_file(system_params()))
    assert runtime.start(), runtime.error
    runtime._on_signal(signal.SIGINT, None)
    result = runtime.stop()
    assert (result.exit_code, result.reason) == (0, "received SIGINT")
