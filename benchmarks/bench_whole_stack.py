"""Benchmark: CPU and memory of the whole `easynav run` process over a patrol, two stacks.

The playground robot patrols a world's waypoints (repeated to fill ``--minutes`` of simulated
time at real-time speed) once with the stack under test (default: the costmap stack with MPPI at
20 Hz) and once with the reference stack (the simple stack), in the same run on the same world.
A sampler reads the EasyNav process's CPU time and resident memory from /proc every second.

Figures: CPU in % of one core (CPU seconds / wall seconds over the patrol) and resident memory
(median and maximum), each beside the reference stack's. Goal (issue #21): <= 60 % of one core
and <= 250 MB (anchors: the C++ original on a Raspberry Pi 4 97.5 % and 115.8 MB; Nav2 144 % and
190 MB).

    .venv/bin/python benchmarks/bench_whole_stack.py [--minutes 10] [--world depot]
        [--params params/costmap.mppi.params.yaml] [--reference params/playground.params.yaml]
"""

from __future__ import annotations

import argparse
import io
import os
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

import yaml

from easynav.core.benchmarking import BenchRow, add_json_option, report

REPO = Path(__file__).resolve().parent.parent
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
PAGE = os.sysconf("SC_PAGE_SIZE")


def find_easynav(run_dir: Path) -> int | None:
    """The pid of the `easynav run` process of this run (its command line names run_dir)."""
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
    """CPU seconds used so far (user + system, all threads) and resident memory in MB."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        rss_pages = int(Path(f"/proc/{pid}/statm").read_text().split()[1])
    except (OSError, IndexError, ValueError):
        return None
    utime, stime = int(fields[11]), int(fields[12])
    return (utime + stime) / CLOCK_TICKS, rss_pages * PAGE / 1e6


class Sampler(threading.Thread):
    """Samples the EasyNav process of a run every second until stopped."""

    def __init__(self, run_dir: Path) -> None:
        super().__init__(daemon=True)
        self.run_dir = run_dir
        self.samples: list[tuple[float, float, float]] = []  # wall, cpu seconds, rss MB
        self.stop_event = threading.Event()

    def run(self) -> None:
        pid = None
        while not self.stop_event.wait(1.0):
            pid = pid or find_easynav(self.run_dir)
            if pid is None:
                continue
            sample = cpu_seconds_and_rss(pid)
            if sample is None:
                if self.samples:
                    return  # the process ended
                continue
            self.samples.append((time.monotonic(), *sample))

    def figures(self, skip: float = 20.0) -> tuple[float, float, float]:
        """CPU % of one core, median and max RSS (MB), leaving out the first ``skip`` seconds
        (start-up and configuration)."""
        if len(self.samples) < 3:
            raise RuntimeError("too few samples of the EasyNav process")
        start = self.samples[0][0] + skip
        kept = [s for s in self.samples if s[0] >= start] or self.samples
        (w0, c0, _), (w1, c1, _) = kept[0], kept[-1]
        cpu = 100.0 * (c1 - c0) / max(w1 - w0, 1e-9)
        rss = [s[2] for s in kept]
        return cpu, statistics.median(rss), max(rss)


def patrol(world: str, minutes: float, lap_estimate: float) -> list[list[float]]:
    """The world's waypoints repeated to fill about ``minutes`` of driving."""
    from easynav.playground.world_description import WorldDescription

    description = WorldDescription.resolve(world)
    waypoints = yaml.safe_load(description.waypoints_path.read_text())["waypoints"]
    laps = max(1, round(minutes * 60.0 / lap_estimate))
    return [list(w) for w in waypoints] * laps


def measure(params: Path, world: str, waypoints: list, timeout: float) -> tuple:
    from easynav.playground.demo import run_demo

    run_dir = Path(tempfile.mkdtemp(prefix="easynav_bench_stack_"))
    sampler = Sampler(run_dir)
    sampler.start()
    out = io.StringIO()
    code = run_demo(world=world, params_file=params, waypoints=waypoints, output_png=None,
                    timeout=timeout, run_dir=run_dir, stream=out)
    sampler.stop_event.set()
    sampler.join()
    cpu, rss_median, rss_max = sampler.figures()
    reached = out.getvalue().count(" yes ")
    return cpu, rss_median, rss_max, code, reached


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0, help="patrol length (simulated)")
    parser.add_argument("--world", default="depot")
    parser.add_argument("--params", default=str(REPO / "params" / "costmap.mppi.params.yaml"))
    parser.add_argument("--reference", default=str(REPO / "params" / "playground.params.yaml"))
    parser.add_argument("--reference-world", default="home",
                        help="world of the reference stack (the simple stack's own)")
    parser.add_argument("--lap", type=float, default=120.0, help="estimated seconds per lap")
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    timeout = args.minutes * 60.0 * 3 + 120.0
    ours = measure(Path(args.params), args.world, patrol(args.world, args.minutes, args.lap),
                   timeout)
    ref = measure(Path(args.reference), args.reference_world,
                  patrol(args.reference_world, args.minutes, args.lap / 2), timeout)
    name, ref_name = Path(args.params).name, Path(args.reference).name
    print(f"{name}: exit {ours[3]}, {ours[4]} waypoints reached; "
          f"{ref_name}: exit {ref[3]}, {ref[4]} reached\n")
    report(
        [
            BenchRow(f"CPU of easynav run, {name}", ours[0], "% of a core",
                     f"{ref_name} (simple stack)", ref[0], goal="<= 60 %", met=ours[0] <= 60.0),
            BenchRow(f"resident memory, {name}, median", ours[1], "MB",
                     f"{ref_name} (simple stack)", ref[1], goal="<= 250 MB",
                     met=ours[1] <= 250.0),
            BenchRow(f"resident memory, {name}, max", ours[2], "MB",
                     f"{ref_name} (simple stack)", ref[2], goal="<= 250 MB",
                     met=ours[2] <= 250.0),
        ],
        args.json,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
