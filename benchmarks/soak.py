"""Soak: an hour of simulated patrol on the warehouse, faster than real time; ``make soak``.

The playground robot patrols the warehouse's waypoints, lap after lap, until ``--minutes`` of
simulated driving are covered, with the costmap stack (``params/costmap.params.yaml``) at
``--speed-up`` simulated seconds per wall second. A sampler reads the ``easynav run`` process's
CPU time and resident memory from /proc every second. Written to ``docs/soak.md`` (with the
memory plot ``docs/soak_memory.png``):

- goals reached, collisions, late RT cycles (EasyNav's heartbeat), the achieved speed-up;
- CPU in % of one core and resident memory over the patrol;
- memory growth after the first 5 minutes: the median RSS of the last 5 simulated minutes
  against the median of minutes 5 to 10, in %.

Goal (issue #21): memory growth below 5 % after the first 5 minutes, no collision, every goal
reached. Simulated minutes are placed on the wall-clock samples with the run's achieved
real-time factor (simulated seconds per wall second, averaged over the run).

    .venv/bin/python benchmarks/soak.py [--minutes 60] [--speed-up 3] [--world warehouse]
        [--params params/costmap.params.yaml] [--out docs/soak.md] [--json rows.json]
"""

from __future__ import annotations

import argparse
import io
import json
import platform
import statistics
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.playground.instruments.process_sampler import ProcessSampler

REPO = Path(__file__).resolve().parent.parent
GOAL_GROWTH = 5.0  # % after the first 5 minutes
WARM_UP = 5.0  # simulated minutes left out of the growth figure


def patrol(world: str, minutes: float, lap_minutes: float) -> list[list[float]]:
    """The world's waypoints, lap after lap, to fill about ``minutes`` of driving."""
    import yaml

    from easynav.playground.world_description import WorldDescription

    description = WorldDescription.resolve(world)
    waypoints = yaml.safe_load(description.waypoints_path.read_text())["waypoints"]
    laps = max(1, round(minutes / lap_minutes))
    return [list(w) for w in waypoints] * laps


def memory_growth(minutes: list[float], rss: list[float], total: float) -> tuple[float, float]:
    """% growth of the median RSS over the last 5 minutes against minutes 5 to 10, and that
    early median (MB)."""
    early = [r for m, r in zip(minutes, rss, strict=True) if WARM_UP <= m < 2 * WARM_UP]
    late = [r for m, r in zip(minutes, rss, strict=True) if m >= total - WARM_UP]
    if not early or not late:
        raise RuntimeError("the patrol is too short for the memory growth figure (>= 15 min)")
    base = statistics.median(early)
    return 100.0 * (statistics.median(late) - base) / base, base


def plot(minutes: list[float], rss: list[float], path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(minutes, rss, lw=1.0)
    ax.axvline(WARM_UP, color="grey", ls=":", lw=1.0)
    ax.set_xlabel("simulated minutes of patrol")
    ax.set_ylabel("resident memory (MB)")
    ax.set_title(title, fontsize=10)
    ax.set_ylim(0, max(rss) * 1.15)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0, help="simulated patrol length")
    parser.add_argument("--speed-up", type=float, default=3.0,
                        help="simulated seconds per wall second")
    parser.add_argument("--world", default="warehouse")
    parser.add_argument("--params", default=str(REPO / "params" / "costmap.params.yaml"))
    parser.add_argument("--lap", type=float, default=2.5, help="estimated minutes per lap")
    parser.add_argument("--out", default=str(REPO / "docs" / "soak.md"))
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()

    from easynav.playground.demo import run_demo

    waypoints = patrol(args.world, args.minutes, args.lap)
    run_dir = Path(tempfile.mkdtemp(prefix="easynav_soak_"))
    sampler = ProcessSampler(run_dir)
    sampler.start()
    out = io.StringIO()
    wall_start = time.monotonic()
    code = run_demo(world=args.world, params_file=args.params, waypoints=waypoints,
                    speed_up=args.speed_up, output_png=None,
                    timeout=args.minutes * 60.0 / args.speed_up * 4 + 300.0,
                    run_dir=run_dir, stream=out)
    wall = time.monotonic() - wall_start
    sampler.stop()
    print(out.getvalue()[-3000:])
    summary = json.loads((run_dir / "summary.json").read_text())
    factor = summary["real_time_factor"] or args.speed_up
    t0 = sampler.samples[0][0]
    minutes = [(s[0] - t0) * factor / 60.0 for s in sampler.samples]
    rss = [s[2] for s in sampler.samples]
    total = minutes[-1]
    growth, early_rss = memory_growth(minutes, rss, total)
    cpu, rss_median, rss_max = sampler.figures()
    reached, goals, collisions = summary["reached"], summary["waypoints"], summary["collisions"]
    late = summary["late_rt_cycles"]

    rows = [
        BenchRow("memory growth after the first 5 minutes", growth, "%",
                 "median RSS of minutes 5-10 (MB)", early_rss,
                 goal=f"< {GOAL_GROWTH:g} %", met=growth < GOAL_GROWTH),
        BenchRow("goals reached", reached, "goals", "goals sent", goals,
                 goal="every goal reached", met=reached == goals),
        BenchRow("collisions", collisions, "collisions", "none", 0,
                 goal="no collision", met=collisions == 0),
    ]
    report(rows, args.json)

    out_md = Path(args.out)
    out_md.parent.mkdir(parents=True, exist_ok=True)
    png = out_md.with_name("soak_memory.png")
    name = Path(args.params).name
    plot(minutes, rss, png, f"easynav run, {name}, {args.world}: resident memory")
    date = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    verdict = all(r.met for r in rows) and code == 0
    lines = [
        "# Soak",
        "",
        "Written by `make soak` (benchmarks/soak.py): the playground robot patrols the "
        f"{args.world} world lap after lap with `params/{name}` for {total:.0f} simulated "
        "minutes, faster than real time; the `easynav run` process is sampled from /proc "
        "every second.",
        "",
        f"- date: {date}; machine: {platform.machine()}, {_cores()} cores, Python "
        f"{platform.python_version()}; load average at the end {_load()}",
        f"- requested speed-up x{args.speed_up:g}, achieved x{factor:.2f}; wall time "
        f"{wall / 60.0:.1f} min; demo exit code {code}",
        "",
        "| figure | value | goal | met |",
        "|---|---|---|---|",
        f"| goals reached | {reached} / {goals} | every goal | {_yes(reached == goals)} |",
        f"| collisions | {collisions} | none | {_yes(collisions == 0)} |",
        f"| memory growth after the first 5 min (median RSS of the last 5 min vs minutes "
        f"5-10) | {growth:+.2f} % | < {GOAL_GROWTH:g} % | {_yes(growth < GOAL_GROWTH)} |",
        f"| resident memory, median / max | {rss_median:.0f} / {rss_max:.0f} MB | | |",
        f"| CPU of easynav run | {cpu:.0f} % of one core (at x{factor:.2f} real time) | | |",
        f"| late RT cycles (EasyNav's heartbeat) | {late} | | |",
        "",
        f"Verdict: {'green' if verdict else 'red'}.",
        "",
        f"![resident memory over the patrol]({png.name})",
        "",
    ]
    out_md.write_text("\n".join(lines))
    print(f"written: {out_md} and {png}")
    return 0 if verdict else 1


def _yes(flag: bool) -> str:
    return "yes" if flag else "**no**"


def _cores() -> int:
    import os

    return os.cpu_count() or 1


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "?"


if __name__ == "__main__":
    sys.exit(main())
