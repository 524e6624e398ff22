"""StopSignals: Ctrl-C and SIGTERM are noted while the demo spins and raised where it checks."""

from __future__ import annotations

import os
import signal

import pytest

from easynav.playground.demo.stop_signals import StopSignals


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_stop_signal_is_raised_at_the_check_not_where_it_arrives(sig):
    before = signal.getsignal(sig)
    with StopSignals() as stop:
        os.kill(os.getpid(), sig)  # handled at the next line of Python: no exception here
        assert stop.requested
        with pytest.raises(KeyboardInterrupt):
            stop.check()
        stop.check()  # once only
    assert signal.getsignal(sig) is before
