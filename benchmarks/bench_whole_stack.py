"""Benchmark: CPU and memory of the whole `easynav run` process over a patrol, two stacks.

The playground robot patrols a world's waypoints (repeated to fill ``--minutes`` of simulated
time at real-time speed) once with the stack under test (default: the costmap stack with MPPI at
20 Hz) and once with the reference stack (the simple stack), in the same run on the same world.
A sampler reads the EasyNav process's CPU time and resident memory from /proc every second.

Figures: CPU in % of one core (CPU seconds / wall seconds over the patrol, the process's and its
children's) and resident memory (median and maximum), each beside the reference stack's. These
are the steady state: numba's kernels loaded from its disk cache, as on every run after the
first. Before them, a shorter first run of the stack under test starts from an empty numba cache
(the first run after installing): its kernels are compiled then (by child processes, see
easynav.common.compiled_kernels), and its memory and CPU are reported beside the steady run's.
All runs share one numba cache directory of their own, empty at the start.

Goal (issue #21): <= 60 % of one core and <= 250 MB (anchors: the C++ original on a Raspberry
Pi 4 97.5 % and 115.8 MB; Nav2 144 % and 190 MB).

    .venv/bin/python benchmarks/bench_whole_stack.py [--minutes 10] [--first-run-minutes 3]
        [--world depot] [--params params/costmap.mppi.params.yaml]
        [--reference params/playground.params.yaml]
"""

from __future__ import annotations

import argparse
import io
import os
import sys
import tempfile
from pathlib import Path

import yaml

from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.playground.instruments.process_sampler import ProcessSampler

REPO = Path(__file__).resolve().parent.parent


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
    sampler = ProcessSampler(run_dir)
    sampler.start()
    out = io.StringIO()
    code = run_demo(world=world, params_file=params, waypoints=waypoints, output_png=None,
                    timeout=timeout, run_dir=run_dir, stream=out)
    sampler.stop()
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
    parser.add_argument("--first-run-minutes", type=float, default=3.0,
                        help="patrol of the first run, from an empty numba cache (0: none)")
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    # One numba cache for this benchmark's runs, empty at the start: the first run compiles
    # the kernels, the later ones load them, whatever the machine's own caches hold.
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="easynav_bench_numba_")
    first = None
    if args.first_run_minutes > 0:
        first = measure(Path(args.params), args.world,
                        patrol(args.world, args.first_run_minutes, args.lap),
                        args.first_run_minutes * 60.0 * 3 + 180.0)
    timeout = args.minutes * 60.0 * 3 + 120.0
    ours = measure(Path(args.params), args.world, patrol(args.world, args.minutes, args.lap),
                   timeout)
    ref = measure(Path(args.reference), args.reference_world,
                  patrol(args.reference_world, args.minutes, args.lap / 2), timeout)
    name, ref_name = Path(args.params).name, Path(args.reference).name
    print(f"{name}: exit {ours[3]}, {ours[4]} waypoints reached; "
          f"{ref_name}: exit {ref[3]}, {ref[4]} reached" + (
              f"; first run: exit {first[3]}, {first[4]} reached" if first else "") + "\n")
    first_rows = [] if first is None else [
        BenchRow(f"CPU of easynav run, {name}, first run (empty numba cache)", first[0],
                 "% of a core", f"{name}, kernels loaded from the cache", ours[0]),
        BenchRow(f"resident memory, {name}, first run (empty numba cache), max", first[2],
                 "MB", f"{name}, kernels loaded from the cache", ours[2], goal="<= 250 MB",
                 met=first[2] <= 250.0),
    ]
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
            *first_rows,
        ],
        args.json,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
