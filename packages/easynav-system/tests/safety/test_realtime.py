"""SCHED_FIFO trial and thread priority, memory locking (where permitted: root here and CI)."""

import os
import resource
import subprocess
import sys
import textwrap
import threading

import pytest

from easynav.system.safety import realtime
from easynav.system.safety.realtime import (
    CAP_IPC_LOCK,
    has_capability,
    lock_memory,
    memlock_allowed,
    set_thread_realtime,
    try_sched_fifo,
)

IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
needs_root = pytest.mark.skipif(
    not IS_ROOT, reason="SCHED_FIFO and mlockall need root (or RLIMIT_RTPRIO/MEMLOCK granted)"
)


def fifo_allowed() -> bool:
    return IS_ROOT and try_sched_fifo()[0]


@pytest.mark.rt
@needs_root
def test_sched_fifo_trial_succeeds_and_leaves_the_caller_unchanged():
    if not fifo_allowed():
        pytest.skip("root, but SCHED_FIFO is refused here (container without SYS_NICE?)")
    before = os.sched_getscheduler(0)
    ok, message = try_sched_fifo(80)
    assert ok, message
    assert message == "SCHED_FIFO priority 80"
    assert os.sched_getscheduler(0) == before


@pytest.mark.rt
@needs_root
def test_set_thread_realtime_applies_to_the_calling_thread_only():
    if not fifo_allowed():
        pytest.skip("root, but SCHED_FIFO is refused here (container without SYS_NICE?)")
    seen = {}

    def worker():
        seen["result"] = set_thread_realtime(80)
        seen["policy"] = os.sched_getscheduler(0)
        seen["priority"] = os.sched_getparam(0).sched_priority

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join()
    assert seen["result"][0]
    assert seen["policy"] == os.SCHED_FIFO and seen["priority"] == 80
    assert os.sched_getscheduler(0) != os.SCHED_FIFO


def test_eperm_gives_a_clear_message(monkeypatch):
    def refuse(*_args):
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(realtime.os, "sched_setscheduler", refuse)
    ok, message = try_sched_fifo(80)
    assert not ok
    assert "SCHED_FIFO priority 80 not permitted (EPERM)" in message
    assert "RLIMIT_RTPRIO" in message and "LimitRTPRIO" in message and "ulimit -r" in message


def test_an_invalid_priority_is_rejected():
    with pytest.raises(ValueError, match="priority 0"):
        set_thread_realtime(0)
    with pytest.raises(ValueError, match="priority 100"):
        try_sched_fifo(100)


def test_memlock_refused_with_a_finite_limit_and_no_capability(monkeypatch):
    monkeypatch.setattr(realtime.resource, "getrlimit", lambda _which: (8 << 20, 8 << 20))
    monkeypatch.setattr(realtime, "has_capability", lambda _bit: False)
    ok, message = memlock_allowed()
    assert not ok
    assert "RLIMIT_MEMLOCK unlimited" in message and "8388608 bytes" in message
    assert "LimitMEMLOCK=infinity" in message and "ulimit -l" in message
    locked, why = lock_memory()  # refuses first: nothing is locked
    assert not locked and why == message


def test_memlock_allowed_when_unlimited(monkeypatch):
    infinity = resource.RLIM_INFINITY
    monkeypatch.setattr(realtime.resource, "getrlimit", lambda _which: (infinity, infinity))
    assert memlock_allowed() == (True, "RLIMIT_MEMLOCK is unlimited")


@pytest.mark.rt
@pytest.mark.skipif(
    not (IS_ROOT or has_capability(CAP_IPC_LOCK)),
    reason="mlockall with MCL_FUTURE needs CAP_IPC_LOCK (root) or RLIMIT_MEMLOCK unlimited",
)
def test_lock_memory_locks_the_process_in_a_subprocess():
    # Locking the pytest process would lock all of its memory: do it in a child process and
    # read VmLck from the kernel.
    script = textwrap.dedent(
        """
        from easynav.system.safety import lock_memory
        ok, message = lock_memory()
        locked = [l for l in open("/proc/self/status") if l.startswith("VmLck:")][0]
        print(ok, int(locked.split()[1]), message)
        """
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    ok, locked_kb, *message = result.stdout.split()
    assert ok == "True", " ".join(message)
    assert int(locked_kb) > 1000
