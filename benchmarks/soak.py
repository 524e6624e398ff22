"""Soak: an hour of simulated patrol on the warehouse, faster than real time; ``make soak``.

The playground robot patrols the warehouse's waypoints with the costmap stack
(``params/costmap.params.yaml``) at ``--speed-up`` simulated seconds per wall second: one lap
of the waypoints per goal-manager mission, lap after lap, until ``--minutes`` simulated
minutes of patrol have passed; then the goal being driven to is finished (the rest of the lap
is dropped by a goal update that keeps only that goal) and the soak ends. A sampler reads the
``easynav run`` process's CPU time and resident memory from /proc every second. Written to
``docs/soak.md`` (with the memory plot ``docs/soak_memory.png``):

- goals reached, collisions, the simulated duration actually run, the achieved speed-up;
- late RT cycles: EasyNav's own count (``RTCycleMonitor``: a cycle starting more than
  ``safety.rt_monitor.max_period_factor`` periods of ``rt_freq`` after the previous one, on
  the monotonic clock), read from ``easynav_heartbeat``, which the soak switches on
  (``safety.heartbeat.period`` 1 s in a derived params file: it is off by default, which left
  the figure empty before), and its share of the cycles the RT loop ran meanwhile
  (``rt_freq`` times the wall time between the heartbeats);
- CPU in % of one core and resident memory over the patrol;
- memory growth after the first 5 minutes: the median RSS of the last 5 simulated minutes
  against the median of minutes 5 to 10, in % (only for patrols of 15 minutes or more).

Goal (issue #21): memory growth below 5 % after the first 5 minutes, no collision, every goal
reached. The sampler's wall-clock samples are placed on simulated minutes with the (wall,
simulated) time pairs read during the patrol.

    .venv/bin/python benchmarks/soak.py [--minutes 60] [--speed-up 3] [--world warehouse]
        [--params params/costmap.params.yaml] [--out|--output docs/soak.md] [--json rows.json]

``--minutes 3 --output /tmp/soak.md`` makes a quick trial (no memory growth figure under 15
simulated minutes: the report says so and the verdict is "incomplete", exit code 1).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import yaml

from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.playground.instruments.process_sampler import ProcessSampler

REPO = Path(__file__).resolve().parent.parent
GOAL_GROWTH = 5.0  # % after the first 5 minutes
WARM_UP = 5.0  # simulated minutes left out of the growth figure
HEARTBEAT_PERIOD = 1.0  # s (wall), easynav_heartbeat during the soak
SPIN_STEP = 0.05  # s per executor wait
READY_TIMEOUT = 90.0  # wall s for the playground and the goal manager


def memory_growth(minutes: list[float], rss: list[float], total: float) -> tuple[float, float]:
    """% growth of the median RSS over the last 5 minutes against minutes 5 to 10, and that
    early median (MB). Raises RuntimeError for a patrol too short for the figure."""
    early = [r for m, r in zip(minutes, rss, strict=True) if WARM_UP <= m < 2 * WARM_UP]
    late = [r for m, r in zip(minutes, rss, strict=True) if m >= total - WARM_UP]
    if total < 3 * WARM_UP or not early or not late:
        raise RuntimeError("the patrol is too short for the memory growth figure (>= 15 min)")
    base = statistics.median(early)
    return 100.0 * (statistics.median(late) - base) / base, base


def with_heartbeat(params_path: Path, out_path: Path) -> dict:
    """Write ``out_path``: the params file with ``system_node``'s heartbeat on (every
    HEARTBEAT_PERIOD s); returns system_node's parameters (as written)."""
    from easynav.system.cli.params_file import load_ros_yaml

    params = load_ros_yaml(Path(params_path).read_text())
    system = params.setdefault("system_node", {}).setdefault("ros__parameters", {})
    system.pop("safety.heartbeat.period", None)
    safety = system.setdefault("safety", {})
    safety.setdefault("heartbeat", {})["period"] = HEARTBEAT_PERIOD
    out_path.write_text(yaml.safe_dump(params, sort_keys=False))
    return system


def rt_loop_settings(system: dict) -> tuple[float, float]:
    """``(rt_freq, max_period_factor)`` of system_node: from the params, else the defaults."""
    from easynav.system.node_declarations import (
        SAFETY_PARAMETERS,
        SYSTEM_PARAMETERS_BY_NAME,
    )

    def get(dotted: str):
        if dotted in system:
            return system[dotted]
        node = system
        for part in dotted.split("."):
            if not isinstance(node, dict) or part not in node:
                return None
            node = node[part]
        return node

    safety_defaults = {p.name: p.default for p in SAFETY_PARAMETERS}
    rt_freq = get("rt_freq")
    factor = get("safety.rt_monitor.max_period_factor")
    return (
        float(rt_freq if rt_freq is not None else SYSTEM_PARAMETERS_BY_NAME["rt_freq"].default),
        float(factor if factor is not None
              else safety_defaults["safety.rt_monitor.max_period_factor"]),
    )


@dataclass
class Patrol:
    """What the patrol did: goals, times, and what was seen of EasyNav meanwhile."""

    results: list = field(default_factory=list)  # WaypointResult, every goal aimed at
    final_state: str = "NOT STARTED"
    status_message: str = ""
    laps: int = 0
    nav_start: float = math.nan  # simulated s
    nav_end: float = math.nan
    wall_start: float = math.nan  # monotonic s
    wall_end: float = math.nan
    clock: list = field(default_factory=list)  # (monotonic s, simulated s) pairs
    heartbeats: list = field(default_factory=list)  # (monotonic s, late cycles)
    collision_count: int = 0
    command_rate: float = 0.0
    estimates: list = field(default_factory=list)
    paths: list = field(default_factory=list)


def run_patrol(children, domain, path_topic, waypoints, minutes, timeout, log) -> Patrol:
    """Start the children, patrol until ``minutes`` simulated minutes have passed (then finish
    the current goal), stop the children. ``log(text)`` reports progress."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from easynav.core.types import Header, Pose, PoseStamped
    from easynav.playground.demo.run_monitor import RunMonitor
    from easynav.playground.demo.waypoint_result import WaypointResult
    from easynav.system.goals.goal_client_state import GoalClientState as S
    from easynav.system.goals.goal_manager_client import GoalManagerClient

    class SoakMonitor(RunMonitor):
        """RunMonitor that also keeps when each heartbeat arrived (wall) with its count."""

        def __init__(self, *args, **kwargs) -> None:
            self.heartbeats: list[tuple[float, int]] = []
            super().__init__(*args, **kwargs)

        def _on_heartbeat(self, msg) -> None:
            super()._on_heartbeat(msg)
            with self.lock:
                self.heartbeats.append((time.monotonic(), int(msg.late_cycles)))

    run = Patrol()
    context = rclpy.Context()
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    rclpy.init(context=context, domain_id=domain)
    executor = SingleThreadedExecutor(context=context)
    monitor = None
    limit = minutes * 60.0
    try:
        for child in children:
            child.start()
        monitor = SoakMonitor(path_topic, context=context)
        executor.add_node(monitor)
        client = GoalManagerClient(monitor)

        def check_children() -> None:
            for child in children:
                if child.exit_code() is not None:
                    raise RuntimeError(
                        f"{child.name} exited with code {child.exit_code()}:\n{child.log_tail()}"
                    )

        def spin_until(predicate, seconds: float, what: str) -> None:
            deadline = time.monotonic() + seconds
            while not predicate():
                check_children()
                if time.monotonic() > deadline:
                    raise RuntimeError(f"timed out after {seconds:.0f} s {what}")
                executor.spin_once(timeout_sec=SPIN_STEP)

        spin_until(lambda: monitor.truth is not None, READY_TIMEOUT, "waiting for the playground")
        spin_until(client.manager_available, READY_TIMEOUT, "waiting for the goal manager")
        run.nav_start = monitor.truth[0]
        run.wall_start = time.monotonic()
        deadline = run.wall_start + timeout
        last_log = 0.0
        stopping = False  # the patrol time is up: the current goal is the last one
        while not stopping:
            trimmed = False  # the lap was cut down to the goal being driven to
            run.laps += 1
            stamp = monitor.get_clock().now().nanoseconds * 1e-9
            lap = [
                WaypointResult(len(run.results) + i, *(float(v) for v in w))
                for i, w in enumerate(waypoints, 1)
            ]
            client.reset()
            client.send_goals(
                [PoseStamped(Header(stamp, "map"), Pose.from_xy_yaw(w.x, w.y, w.yaw))
                 for w in lap]
            )
            spin_until(lambda: client.get_state() is not S.SENT_GOAL, READY_TIMEOUT,
                       "waiting for the goal manager to accept a lap")
            while True:
                state = client.get_state()
                feedback = client.get_feedback()
                now = monitor.truth[0]
                remaining = monitor.remaining_goals
                if feedback is not None and feedback.goals.goals:
                    remaining = min(remaining if remaining is not None else 10**9,
                                    len(feedback.goals.goals))
                if state is S.NAVIGATION_FINISHED:
                    remaining = 0
                if remaining is not None:
                    for w in lap[: max(0, len(lap) - remaining)]:
                        if w.reached_at is None:
                            w.reached_at = now
                if state.is_terminal:
                    run.final_state = state.name
                    result = client.get_result()
                    run.status_message = result.status_message if result else ""
                    break
                if now - run.nav_start >= limit:
                    stopping = True
                if stopping and not trimmed and state is S.ACCEPTED_AND_NAVIGATING:
                    # Finish the goal being driven to, drop the rest of the lap (a goal
                    # update, tried until the client is in a state to send it).
                    trimmed = True
                    current = next((i for i, w in enumerate(lap) if not w.reached), None)
                    if current is not None and current < len(lap) - 1:
                        del lap[current + 1:]
                        w = lap[current]
                        client.send_goals(
                            [PoseStamped(Header(stamp, "map"), Pose.from_xy_yaw(w.x, w.y, w.yaw))]
                        )
                wall = time.monotonic()
                if wall - last_log >= 1.0:
                    last_log = wall
                    run.clock.append((wall, now))
                    reached = sum(w.reached for w in run.results + lap)
                    log(f"lap {run.laps}: {reached} goals reached, "
                        f"{(now - run.nav_start) / 60.0:5.1f} of {minutes:g} simulated min, "
                        f"collisions {monitor.collision_count}")
                check_children()
                if wall > deadline:
                    run.final_state = "TIMEOUT"
                    run.status_message = f"no end within {timeout:.0f} wall s"
                    client.cancel()
                    stopping = True
                    break
                executor.spin_once(timeout_sec=SPIN_STEP)
            run.results += lap
            if run.final_state != S.NAVIGATION_FINISHED.name:
                break
            if monitor.truth[0] - run.nav_start >= limit:
                stopping = True
        run.nav_end = monitor.truth[0]
        run.wall_end = time.monotonic()
        run.clock.append((run.wall_end, run.nav_end))
        # A last heartbeat after the patrol's end (one period), so the count covers all of it.
        end = time.monotonic() + 2.0 * HEARTBEAT_PERIOD
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=SPIN_STEP)
    except RuntimeError as err:
        run.final_state = "ERROR"
        run.status_message = str(err).splitlines()[0]
        print(f"soak: {err}", file=sys.stderr)
        if monitor is not None and monitor.truth is not None and math.isnan(run.nav_end):
            run.nav_end = monitor.truth[0]
            run.wall_end = time.monotonic()
            if math.isnan(run.nav_start):
                run.nav_start, run.wall_start = run.nav_end, run.wall_end
    finally:
        for child in reversed(children):  # EasyNav first (it stops the robot), then the robot
            child.stop()
        executor.shutdown()
        if monitor is not None:
            with monitor.lock:
                run.heartbeats = list(monitor.heartbeats)
                run.collision_count = monitor.collision_count
                run.estimates = list(monitor.estimates.estimated_poses)
                run.paths = list(monitor.paths)
            if not math.isnan(run.nav_start) and not math.isnan(run.nav_end):
                run.command_rate = monitor.command_rate(run.nav_start, run.nav_end)
            monitor.destroy_node()
        rclpy.shutdown(context=context)
    return run


def late_cycles(run: Patrol, rt_freq: float) -> tuple[int | None, int | None, int | None]:
    """Late RT cycles over the patrol (between the last heartbeat at or before its start and
    the first at or after its end), the RT cycles run meanwhile (``rt_freq`` x wall time), and
    the late cycles since EasyNav's activation; Nones without heartbeats."""
    beats = run.heartbeats
    if not beats:
        return None, None, None
    before = [b for b in beats if b[0] <= run.wall_start] or beats[:1]
    after = [b for b in beats if b[0] >= run.wall_end] or beats[-1:]
    first, last = before[-1], after[0]
    cycles = round(rt_freq * (last[0] - first[0]))
    return last[1] - first[1], cycles, beats[-1][1]


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
    parser.add_argument("--minutes", type=float, default=60.0,
                        help="simulated minutes of patrol (then the current goal is finished)")
    parser.add_argument("--speed-up", type=float, default=3.0,
                        help="simulated seconds per wall second")
    parser.add_argument("--world", default="warehouse")
    parser.add_argument("--params", default=str(REPO / "params" / "costmap.params.yaml"))
    parser.add_argument("--out", "--output", dest="out", default=str(REPO / "docs" / "soak.md"))
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    if not (math.isfinite(args.minutes) and args.minutes > 0):
        parser.error("--minutes must be > 0")

    from easynav.playground.demo.child_process import ChildProcess
    from easynav.playground.demo.demo import _easynav_command
    from easynav.playground.demo.params_patch import derive_params
    from easynav.playground.demo.run_summary import RunSummary
    from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
    from easynav.playground.world_description import WorldDescription
    from easynav.system.testing.dds_isolation import reserve_domain

    description = WorldDescription.resolve(args.world)
    waypoints = yaml.safe_load(description.waypoints_path.read_text())["waypoints"]
    run_dir = Path(tempfile.mkdtemp(prefix="easynav_soak_"))
    soak_params = run_dir / "soak.params.yaml"
    system = with_heartbeat(Path(args.params), soak_params)
    rt_freq, period_factor = rt_loop_settings(system)
    map_file = run_dir / "world.map"
    description.world.save_map_file(map_file)
    derived = run_dir / "params.yaml"
    _notes, path_topic = derive_params(
        soak_params, map_file, description.start_pose, derived,
        map_yaml=description.map_server_yaml(run_dir),
        robot_radius=description.robot.radius if description.robot.declared else None,
        robot_height=description.robot.height,
        elevation_file=description.elevation_map(run_dir),
    )
    domain = reserve_domain(f"soak/{os.getpid()}")  # held until the soak exits
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain),
           "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    record = run_dir / "ground_truth.json"
    children = [
        ChildProcess("playground", [sys.executable, "-m", "easynav.playground", "--world",
                                    args.world, "--speed-up", str(args.speed_up), "--seed", "0",
                                    "--record", str(record)], env, run_dir / "playground.log"),
        ChildProcess("easynav", [*_easynav_command(), "run", str(derived)], env,
                     run_dir / "easynav.log"),
    ]
    print(f"soak: {args.world}, {Path(args.params).name}, {args.minutes:g} simulated min at "
          f"x{args.speed_up:g}; logs in {run_dir}")
    sampler = ProcessSampler(run_dir)
    sampler.start()
    wall_start = time.monotonic()
    run = run_patrol(children, domain, path_topic, waypoints, args.minutes,
                     args.minutes * 60.0 / args.speed_up * 4 + 300.0,
                     lambda text: print(f"  {text}", flush=True))
    wall = time.monotonic() - wall_start
    sampler.stop()

    try:
        truth = GroundTruthRecorder.load(record)
    except (OSError, ValueError, KeyError) as err:
        print(f"soak: no ground truth from the playground ({err})", file=sys.stderr)
        truth = GroundTruthRecorder()
    truth.estimated_poses = run.estimates
    summary = RunSummary.compute(run.results, truth, run.final_state, run.status_message,
                                 run.nav_start, run.nav_end, run.command_rate)
    print(summary.format_table()[-3000:])
    (run_dir / "summary.json").write_text(json.dumps(summary.to_dict(), indent=2))

    patrol_min = (run.nav_end - run.nav_start) / 60.0
    factor = (run.nav_end - run.nav_start) / max(run.wall_end - run.wall_start, 1e-9)
    walls, sims = zip(*run.clock, strict=True) if run.clock else ((), ())
    kept = [s for s in sampler.samples if walls and s[0] >= walls[0]]
    minutes = list((np.interp([s[0] for s in kept], walls, sims) - run.nav_start) / 60.0)
    rss = [s[2] for s in kept]
    try:
        growth, early_rss = memory_growth(minutes, rss, patrol_min)
    except RuntimeError as err:
        print(f"soak: {err}")
        growth = early_rss = None
    cpu, rss_median, rss_max = sampler.figures()
    reached, goals = sum(w.reached for w in run.results), len(run.results)
    collisions = len(summary.collisions)
    late, cycles, late_total = late_cycles(run, rt_freq)
    share = 100.0 * late / cycles if late is not None and cycles else None
    tolerance_ms = 1e3 * period_factor / rt_freq

    rows = [
        BenchRow("goals reached", reached, "goals", "goals sent", goals,
                 goal="every goal reached", met=reached == goals and goals > 0),
        BenchRow("collisions", collisions, "collisions", "none", 0,
                 goal="no collision", met=collisions == 0),
        BenchRow("simulated patrol", patrol_min, "min", "requested", args.minutes,
                 goal=f">= {args.minutes:g} min", met=patrol_min >= args.minutes),
    ]
    if growth is not None:
        rows.insert(0, BenchRow("memory growth after the first 5 minutes", growth, "%",
                                "median RSS of minutes 5-10 (MB)", early_rss,
                                goal=f"< {GOAL_GROWTH:g} %", met=growth < GOAL_GROWTH))
    if late is not None:
        rows.append(BenchRow("late RT cycles", late, "cycles", "RT cycles run", cycles))
    report(rows, args.json)

    out_md = Path(args.out)
    out_md.parent.mkdir(parents=True, exist_ok=True)
    png = out_md.with_name("soak_memory.png") if out_md.name == "soak.md" else \
        out_md.with_suffix(".png")
    name = Path(args.params).name
    if rss:
        plot(minutes, rss, png, f"easynav run, {name}, {args.world}: resident memory")
    date = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    complete = run.final_state == "NAVIGATION_FINISHED" and growth is not None
    verdict = all(r.met for r in rows if r.met is not None) and complete
    growth_cell = (
        f"{growth:+.2f} % | < {GOAL_GROWTH:g} % | {_yes(growth < GOAL_GROWTH)}"
        if growth is not None else "not measured (patrol under 15 simulated min) | < 5 % | -"
    )
    if late is None:
        late_cell = "none received (no easynav_heartbeat)"
    else:
        late_cell = (f"{late} of about {cycles} ({share:.2f} %) during the patrol; "
                     f"{late_total} since activation")
    lines = [
        "# Soak",
        "",
        "Written by `make soak` (benchmarks/soak.py): the playground robot patrols the "
        f"{args.world} world lap after lap (one goal-manager mission per lap of "
        f"{len(waypoints)} waypoints) with `params/{name}` until {args.minutes:g} simulated "
        "minutes have passed, then finishes the goal it is driving to; faster than real time. "
        "The `easynav run` process is sampled from /proc every second.",
        "",
        f"- date: {date}; commit {_commit()}; machine: {platform.machine()}, {_cores()} "
        f"cores, Python "
        f"{platform.python_version()}; load average at the end {_load()}",
        f"- simulated patrol: {patrol_min:.1f} min ({args.minutes:g} requested), {run.laps} "
        f"lap(s) begun; result {run.final_state}"
        + (f" ({run.status_message})" if run.status_message else ""),
        f"- requested speed-up x{args.speed_up:g}, achieved x{factor:.2f}; wall time "
        f"{wall / 60.0:.1f} min",
        "",
        "| figure | value | goal | met |",
        "|---|---|---|---|",
        f"| goals reached | {reached} / {goals} | every goal | {_yes(reached == goals)} |",
        f"| collisions | {collisions} | none | {_yes(collisions == 0)} |",
        f"| memory growth after the first 5 min (median RSS of the last 5 min vs minutes "
        f"5-10) | {growth_cell} |",
        f"| resident memory, median / max | {rss_median:.0f} / {rss_max:.0f} MB | | |",
        f"| CPU of easynav run | {cpu:.0f} % of one core (at x{factor:.2f} real time) | | |",
        f"| late RT cycles (started > {period_factor:g} periods = {tolerance_ms:.1f} ms after "
        f"the previous one at rt_freq {rt_freq:g} Hz; EasyNav's heartbeat) | {late_cell} | | |",
        "",
        "Late RT cycles are EasyNav's own count (RTCycleMonitor, monotonic clock), read from "
        f"`easynav_heartbeat` (switched on for the soak: `safety.heartbeat.period` "
        f"{HEARTBEAT_PERIOD:g} s); the cycles run are rt_freq x the wall time between the "
        "heartbeats around the patrol (about: the loop skips the cycles of a stall and adds "
        "the ones new sensor data triggers).",
        "",
        f"Verdict: {'green' if verdict else ('red' if complete else 'incomplete')}.",
        "",
        f"![resident memory over the patrol]({png.name})",
        "",
    ]
    out_md.write_text("\n".join(lines))
    print(f"written: {out_md} and {png}")
    return 0 if verdict else 1


def _yes(flag: bool) -> str:
    return "yes" if flag else "**no**"


def _commit() -> str:
    """The commit the soak ran (short hash, ``+changes`` when the tree differs): its figures
    describe that code."""
    def git(*args: str) -> str:
        done = subprocess.run(["git", *args], cwd=REPO, capture_output=True, text=True)
        return done.stdout.strip() if done.returncode == 0 else ""

    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    return commit + ("+changes" if git("status", "--porcelain", "--untracked-files=no") else "")


def _cores() -> int:
    return os.cpu_count() or 1


def _load() -> str:
    try:
        return Path("/proc/loadavg").read_text().split()[0]
    except OSError:
        return "?"


if __name__ == "__main__":
    sys.exit(main())
