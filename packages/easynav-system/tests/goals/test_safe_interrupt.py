"""SafeInterrupt: Ctrl-C is counted, never raised inside whatever the main thread is running."""

from __future__ import annotations

import os
import signal
import threading

import pytest

from easynav.system.goals.safe_interrupt import SafeInterrupt


def test_a_press_is_counted_and_raised_only_at_check():
    previous = signal.getsignal(signal.SIGINT)
    with SafeInterrupt() as interrupt:
        os.kill(os.getpid(), signal.SIGINT)  # handled before kill returns (main thread)
        assert interrupt.presses == 1
        with pytest.raises(KeyboardInterrupt):
            interrupt.check()
        interrupt.check(seen=1)  # a press already dealt with does not raise again
        os.kill(os.getpid(), signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):
            interrupt.check(seen=1)
    assert signal.getsignal(signal.SIGINT) is previous


def test_outside_the_main_thread_it_installs_nothing():
    seen = {}

    def body():
        with SafeInterrupt() as interrupt:
            seen["handler"] = signal.getsignal(signal.SIGINT)
            interrupt.check()
            seen["presses"] = interrupt.presses

    previous = signal.getsignal(signal.SIGINT)
    thread = threading.Thread(target=body)
    thread.start()
    thread.join()
    assert seen == {"handler": previous, "presses": 0}
