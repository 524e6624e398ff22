"""Repository-wide pytest set-up: every test process gets a ROS domain of its own.

Where the runtime (easynav-system) is not installed (the kernel or a plugin distribution tested
alone, without ROS), there is no ROS to isolate and no ROS fixture to offer.
"""

import gc
import importlib.util
import os
import sys
import tempfile
import threading
import time

if importlib.util.find_spec("easynav.system") is not None:
    from easynav.system.testing.dds_isolation import isolate_dds

    isolate_dds()
    # Saved configurations and ROS logs of test runs stay out of the user's ~/.ros/log.
    os.environ.setdefault("ROS_LOG_DIR", tempfile.mkdtemp(prefix="easynav-test-logs-"))

    pytest_plugins = [
        "easynav.system.testing.ros_fixtures",
        "easynav.system.testing.system_fixtures",
    ]


# The machine's load during the run, at the end of the report: a timing test that failed on a
# machine busy with other work (another test run, a matrix mission, a neighbour on the
# hypervisor) says so here. Linux only (/proc/stat); the controller process only, not xdist's
# workers (whose CPU time it counts, as its children).
def _cpu_seconds() -> tuple[float, float, float, float] | None:
    """Machine-wide busy, idle and stolen CPU seconds (/proc/stat), and this process tree's."""
    import resource

    try:
        with open("/proc/stat") as stat:
            fields = [int(value) for value in stat.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    tick = os.sysconf("SC_CLK_TCK")
    idle = (fields[3] + fields[4]) / tick  # idle + iowait
    steal = fields[7] / tick if len(fields) > 7 else 0.0
    busy = sum(fields[:8]) / tick - idle - steal  # user .. softirq (guest is inside user)
    usages = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    own = sum(usage.ru_utime + usage.ru_stime for usage in usages)
    return busy, idle, steal, own


_cpu_at_start: list = []


def pytest_sessionstart(session) -> None:
    if not hasattr(session.config, "workerinput"):
        _cpu_at_start.append(_cpu_seconds())


def pytest_terminal_summary(terminalreporter, config) -> None:
    start = _cpu_at_start[0] if _cpu_at_start else None
    end = _cpu_seconds()
    if start is None or end is None:
        return
    busy, idle, steal, own = (b - a for a, b in zip(start, end, strict=True))
    total = busy + idle + steal
    if total <= 0:
        return
    others = max(0.0, busy - own)
    terminalreporter.write_line(
        f"machine during the tests: {os.cpu_count()} CPUs, {100 * busy / total:.0f}% busy "
        f"(these tests {100 * min(own, busy) / total:.0f}%, other processes "
        f"{100 * others / total:.0f}%), {100 * steal / total:.0f}% stolen by the hypervisor"
    )


# Long garbage collections, in the output of the test they happened in: a collection holds the
# GIL, and the finalizers it runs (an earlier test's ROS objects among them) run in whichever
# thread triggered it, an EasyNav loop's too. A test whose loops stood still says so here.
_GC_REPORTED_AFTER = 0.2  # s
_gc_started: dict[int, float] = {}


def _time_garbage_collection(phase: str, info: dict) -> None:
    thread = threading.get_ident()
    if phase == "start":
        _gc_started[thread] = time.perf_counter()
        return
    started = _gc_started.pop(thread, None)
    if started is None:
        return
    took = time.perf_counter() - started
    if took >= _GC_REPORTED_AFTER:
        sys.stderr.write(
            f"[conftest] a garbage collection (generation {info.get('generation')}, "
            f"{info.get('collected')} objects) took {took:.2f} s in thread "
            f"{threading.current_thread().name}\n"
        )


def _install_garbage_collection_timer() -> None:
    if _time_garbage_collection not in gc.callbacks:
        gc.callbacks.append(_time_garbage_collection)


_install_garbage_collection_timer()
