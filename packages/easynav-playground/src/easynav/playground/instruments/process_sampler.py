"""ProcessSampler: CPU time and resident memory of a run's ``easynav run`` process, over time.

The benchmarks of the whole stack (CPU and memory over a patrol) and the soak (memory over an
hour) watch EasyNav from outside, as an integrator's monitoring would: /proc, once a second.
"""

from __future__ import annotations

import os
import statistics
import threading
import time
from pathlib import Path

CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
PAGE = os.sysconf("SC_PAGE_SIZE")


def find_easynav(run_dir: Path) -> int | None:
    """The pid of the ``easynav run`` process of a demo run (its command line names run_dir)."""
    marker = str(run_dir)
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        if " run " in cmdline and marker in cmdline and "easynav" in cmdline:
            return int(entry.name)
    return None


def cpu_seconds_and_rss(pid: int) -> tuple[float, float] | None:
    """CPU seconds used so far (user + system, all threads, and the children it has waited for:
    numba kernels compiled by a child process count as the run's) and resident memory in MB;
    None when the process is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        rss_pages = int(Path(f"/proc/{pid}/statm").read_text().split()[1])
    except (OSError, IndexError, ValueError):
        return None
    utime, stime, cutime, cstime = (int(f) for f in fields[11:15])
    return (utime + stime + cutime + cstime) / CLOCK_TICKS, rss_pages * PAGE / 1e6


class ProcessSampler(threading.Thread):
    """Samples the EasyNav process of a demo run every ``period`` seconds until stopped or
    until the process ends: :attr:`samples` holds ``(monotonic s, CPU s, RSS MB)``.

    Thread contract: a daemon thread of its own; read :attr:`samples` after :meth:`join`.
    """

    def __init__(self, run_dir: Path, period: float = 1.0) -> None:
        super().__init__(daemon=True, name="easynav-process-sampler")
        self.run_dir = Path(run_dir)
        self.period = period
        self.samples: list[tuple[float, float, float]] = []
        self.stop_event = threading.Event()

    def run(self) -> None:
        pid = None
        while not self.stop_event.wait(self.period):
            pid = pid or find_easynav(self.run_dir)
            if pid is None:
                continue
            sample = cpu_seconds_and_rss(pid)
            if sample is None:
                if self.samples:
                    return  # the process ended
                continue
            self.samples.append((time.monotonic(), *sample))

    def stop(self) -> None:
        """Stop sampling and wait for the thread."""
        self.stop_event.set()
        self.join()

    def figures(self, skip: float = 20.0) -> tuple[float, float, float]:
        """CPU in % of one core, median and maximum RSS (MB), leaving out the first ``skip``
        seconds (start-up and configuration). Raises RuntimeError with fewer than 3 samples."""
        if len(self.samples) < 3:
            raise RuntimeError("too few samples of the EasyNav process")
        start = self.samples[0][0] + skip
        kept = [s for s in self.samples if s[0] >= start] or self.samples
        (w0, c0, _), (w1, c1, _) = kept[0], kept[-1]
        cpu = 100.0 * (c1 - c0) / max(w1 - w0, 1e-9)
        rss = [s[2] for s in kept]
        return cpu, statistics.median(rss), max(rss)
