"""Real-time helpers: SCHED_FIFO for a thread, its trial at configure, and memory locking.

Plain functions over ``os``/``resource``/``ctypes`` (Linux). They never raise for a missing
permission: each returns ``(ok, message)`` and the caller decides whether it is a warning
(outside safety mode) or a failed configure (safety mode, ``safety.lock_memory``).
"""

from __future__ import annotations

import ctypes
import os
import platform
import resource
import threading

#: Linux capability bits (linux/capability.h).
CAP_IPC_LOCK = 14
CAP_SYS_NICE = 23

#: SCHED_FIFO priority of EasyNav's RT thread (the original EasyNav's, with use_real_time true).
RT_PRIORITY = 80

_RTPRIO_HELP = (
    "Grant it with a line '<user> - rtprio 99' in /etc/security/limits.d/ (then log in "
    "again), LimitRTPRIO=99 in a systemd service, or '--ulimit rtprio=99 --cap-add SYS_NICE' "
    "for a container; check with 'ulimit -r' (must be >= {priority})."
)

_MEMLOCK_HELP = (
    "Grant it with a line '<user> - memlock unlimited' in /etc/security/limits.d/ (then log "
    "in again), LimitMEMLOCK=infinity in a systemd service, or '--ulimit memlock=-1:-1' (or "
    "'--cap-add IPC_LOCK') for a container; check with 'ulimit -l' (must print 'unlimited')."
)


def _effective_capabilities() -> int:
    """CapEff of this process from /proc/self/status (0 when it cannot be read)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("CapEff:"):
                    return int(line.split()[1], 16)
    except (OSError, ValueError, IndexError):
        pass
    return 0


def has_capability(bit: int) -> bool:
    """True when this process has the Linux capability ``bit`` in its effective set."""
    return bool(_effective_capabilities() >> bit & 1)


def _limit_text(value: int) -> str:
    return "unlimited" if value == resource.RLIM_INFINITY else str(value)


def set_thread_realtime(priority: int = RT_PRIORITY) -> tuple[bool, str]:
    """Make the **calling thread** SCHED_FIFO at ``priority``; ``(ok, message)``.

    Thread contract: affects only the thread that calls it (Linux ``sched_setscheduler`` with
    pid 0). On EPERM the message says what is missing (RLIMIT_RTPRIO or CAP_SYS_NICE) and how to
    grant it; the thread keeps its normal priority. Raises ``ValueError`` for a priority outside
    SCHED_FIFO's range.
    """
    if not hasattr(os, "SCHED_FIFO"):
        return False, f"SCHED_FIFO is not available on {platform.system()}"
    low = os.sched_get_priority_min(os.SCHED_FIFO)
    high = os.sched_get_priority_max(os.SCHED_FIFO)
    if not (isinstance(priority, int) and low <= priority <= high):
        raise ValueError(f"SCHED_FIFO priority {priority!r} is outside [{low}, {high}]")
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError:
        soft, _hard = resource.getrlimit(resource.RLIMIT_RTPRIO)
        return False, (
            f"SCHED_FIFO priority {priority} not permitted (EPERM): RLIMIT_RTPRIO is "
            f"{_limit_text(soft)} and the process lacks CAP_SYS_NICE. "
            + _RTPRIO_HELP.format(priority=priority)
        )
    except OSError as error:
        return False, f"SCHED_FIFO priority {priority} failed: {error}"
    return True, f"SCHED_FIFO priority {priority}"


def try_sched_fifo(priority: int = RT_PRIORITY) -> tuple[bool, str]:
    """Whether SCHED_FIFO at ``priority`` is allowed, tried on a temporary thread.

    Used at configure in safety mode so nothing is activated without real-time scheduling;
    the calling thread and the process are left unchanged. Thread contract: any thread (it
    starts and joins its own). ``(ok, message)``; ``ValueError`` for an invalid priority.
    """
    result: list[tuple[bool, str]] = []
    error: list[BaseException] = []

    def trial() -> None:
        try:
            result.append(set_thread_realtime(priority))
        except BaseException as exc:  # reported to the caller below, never lost in the thread
            error.append(exc)

    thread = threading.Thread(target=trial, name="easynav_sched_fifo_trial", daemon=True)
    thread.start()
    thread.join(timeout=5.0)
    if error:
        raise error[0]
    if not result:
        return False, "the SCHED_FIFO trial thread did not finish within 5 s"
    return result[0]


def memlock_allowed() -> tuple[bool, str]:
    """Whether locking all memory is safe to ask for: ``(ok, message)``.

    With mlockall(MCL_FUTURE) and a finite RLIMIT_MEMLOCK, later allocations would fail once
    the limit is reached (EasyNav with ROS 2 and DDS uses hundreds of MB, so almost at once),
    so the limit must be unlimited. A process with CAP_IPC_LOCK is not bounded by
    RLIMIT_MEMLOCK (mlock(2)), so it qualifies too.
    """
    soft, _hard = resource.getrlimit(resource.RLIMIT_MEMLOCK)
    if soft == resource.RLIM_INFINITY:
        return True, "RLIMIT_MEMLOCK is unlimited"
    if has_capability(CAP_IPC_LOCK):
        return True, (
            f"RLIMIT_MEMLOCK is {soft} bytes, but the process has CAP_IPC_LOCK, which the "
            "limit does not bound"
        )
    return False, (
        f"safety.lock_memory needs RLIMIT_MEMLOCK unlimited, but it is {soft} bytes: with a "
        "finite limit, allocations would start failing once EasyNav had locked that much. "
        + _MEMLOCK_HELP
    )


def _mcl_flags() -> int:
    # MCL_CURRENT | MCL_FUTURE: 1 | 2 on x86, ARM and most Linux ports; other values on a few.
    machine = platform.machine().lower()
    if machine.startswith(("ppc", "powerpc", "sparc")):
        return 0x2000 | 0x4000
    if machine.startswith("alpha"):
        return 0x2000 | 0x4000
    return 1 | 2


def lock_memory() -> tuple[bool, str]:
    """``mlockall(MCL_CURRENT | MCL_FUTURE)`` for the whole process; ``(ok, message)``.

    Refuses first, without locking anything, when :func:`memlock_allowed` says no. Thread
    contract: system_main's thread, before activating (it affects the whole process, once).
    Never raises for a refusal or a failure; the message says why and how to grant it.
    """
    if platform.system() != "Linux":
        return False, f"memory locking is not supported on {platform.system()}"
    allowed, why = memlock_allowed()
    if not allowed:
        return False, why
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.mlockall(_mcl_flags()) != 0:
        errno = ctypes.get_errno()
        return False, f"mlockall(MCL_CURRENT | MCL_FUTURE) failed: {os.strerror(errno)}. " + (
            _MEMLOCK_HELP
        )
    return True, f"process memory locked (mlockall MCL_CURRENT | MCL_FUTURE); {why}"
