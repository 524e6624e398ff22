"""The playground demo: EasyNav drives the simulated robot through a list of waypoints.

Two processes, like a real robot and its navigation: the playground (``python -m
easynav.playground``) and EasyNav (``easynav run PARAMS``), on a ROS domain of their own so that
parallel runs do not see each other. This process sends the waypoints with GoalManagerClient,
shows the progress, then stops both, prints a summary and draws the run.

Exit codes: 0 every waypoint reached without a collision; 1 otherwise (or a process died, or
the timeout expired); 2 bad arguments; 130 interrupted (Ctrl-C).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path
from typing import TextIO

from easynav.playground.demo.child_process import ChildProcess
from easynav.playground.demo.navmap_params import goal_height, point_navmap_stack_at_world
from easynav.playground.demo.params_patch import (
    derive_params,
    laser_scan_topics,
    planner_plugins,
)
from easynav.playground.demo.progress_line import ProgressLine
from easynav.playground.demo.run_plot import plot_run
from easynav.playground.demo.run_summary import RunSummary
from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.reachability import reachable_from
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.world_description import (
    WorldDescription,
    load_waypoint_levels,
    load_waypoints,
)

EXIT_SUCCESS = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

DEFAULT_PARAMS = Path(
    str(resources.files("easynav.playground") / "params" / "playground.params.yaml")
)
SPIN_STEP = 0.05  # s per executor wait in the main loop
COSTMAP_PLANNER = "easynav_costmap_planner/CostmapPlanner"


class DemoError(Exception):
    """A problem that ends the demo with a message (bad input, a process that died)."""


def _easynav_command() -> list[str]:
    """The ``easynav`` command of this environment (next to the interpreter first)."""
    beside = Path(sys.executable).parent / "easynav"
    if beside.exists():
        return [str(beside)]
    found = shutil.which("easynav")
    if found:
        return [found]
    raise DemoError("the 'easynav' command was not found next to Python or on PATH")


def _domain_for_run(domain_id: int | None):
    """The run's ROS domain: ``domain_id`` when given, else one no other process or run of this
    machine holds, reserved until the run ends (its processes stopped). Returns a
    DomainReservation (``.domain``; ``release()``) or None with the given id."""
    if domain_id is not None:
        return None
    from easynav.core.testing.dds_isolation import DomainReservation

    return DomainReservation.acquire(f"demo/{os.getpid()}")


def run_demo(
    world: str = "home",
    params_file: str | Path | None = None,
    waypoints: str | Path | list[tuple[float, float, float]] | None = None,
    speed_up: float = 1.0,
    output_png: str | Path | None = "easynav_demo.png",
    timeout: float = 600.0,
    seed: int = 0,
    moving_obstacles: bool = True,
    domain_id: int | None = None,
    run_dir: str | Path | None = None,
    ready_timeout: float = 60.0,
    stream: TextIO | None = None,
) -> int:
    """Run the demo; returns the exit code (see the module documentation).

    Args:
        world: a shipped world name, a world description / map-server YAML or a ``.map``.
        params_file: EasyNav params (default: the playground's proposal). Its simple maps
            manager and localizer initial pose are pointed at ``world`` in a derived copy.
        waypoints: a YAML waypoint list or ``[(x, y, yaw), ...]`` (default: the world's).
        speed_up: simulated seconds per wall second.
        output_png: picture of the run (None: no picture).
        timeout: wall seconds before giving up (the navigation is cancelled).
        seed: the playground's noise seed.
        moving_obstacles: include the world's moving obstacles.
        domain_id: ROS domain of the run (default: derived from the pid).
        run_dir: where logs, the derived params and the ground truth go (default: a new
            temporary directory, kept and printed).
        ready_timeout: wall seconds to wait for the playground and the goal manager.
        stream: where progress and the summary are printed (default stdout).

    Thread contract: call from the main thread (it installs nothing global but runs an
    executor and child processes until it returns).
    """
    out = stream or sys.stdout
    try:
        description = WorldDescription.resolve(str(world))
        if waypoints is None:
            if description.waypoints_path is None:
                raise DemoError(f"world {world!r} has no default waypoints: pass --waypoints")
            waypoint_list = load_waypoints(description.waypoints_path)
            waypoint_levels = load_waypoint_levels(description.waypoints_path)
        elif isinstance(waypoints, str | Path):
            waypoint_list = load_waypoints(waypoints)
            waypoint_levels = load_waypoint_levels(waypoints)
        else:
            waypoint_list = [tuple(float(v) for v in w) for w in waypoints]
            waypoint_levels = None
        if not (math.isfinite(speed_up) and speed_up > 0):
            raise DemoError(f"speed-up must be > 0, got {speed_up}")
        params_path = Path(params_file) if params_file else DEFAULT_PARAMS
        run_path = Path(run_dir) if run_dir else Path(tempfile.mkdtemp(prefix="easynav_demo_"))
        run_path.mkdir(parents=True, exist_ok=True)
        map_file = run_path / "world.map"
        description.world.save_map_file(map_file)
        robot = description.robot
        derived = run_path / "params.yaml"
        notes, path_topic = derive_params(
            params_path,
            map_file,
            description.start_pose,
            derived,
            map_yaml=description.map_server_yaml(run_path),
            robot_radius=robot.radius if robot.declared else None,
            robot_height=robot.height,
            terrain_file=(
                description.terrain_path.resolve() if description.terrain_path else None
            ),
        )
        notes = point_navmap_stack_at_world(
            derived, description, description.map_server_yaml(run_path), notes
        )
        costmap_planning = COSTMAP_PLANNER in planner_plugins(params_path)
        scan_topics = laser_scan_topics(params_path)
        easynav = _easynav_command()
    except (OSError, ValueError, DemoError) as err:
        print(f"easynav demo: {err}", file=sys.stderr)
        return EXIT_USAGE

    print(
        f"EasyNav playground demo: world '{description.world.name}', "
        f"{len(waypoint_list)} waypoints, speed-up x{speed_up:g}",
        file=out,
    )
    print(f"  params: {params_path}", file=out)
    for note in notes:
        print(f"  - {note}", file=out)
    starts = [description.start_pose[:2]] + [w[:2] for w in waypoint_list[:-1]]
    if costmap_planning:
        # CostmapPlanner: cells of the map's own grid farther than the robot radius from walls.
        check = {
            "cell_size": description.world.resolution,
            "robot_radius": description.robot.radius,
            "clearance": 0.0,
        }
        rule = (
            f"CostmapPlanner ({description.robot.radius:g} m robot on the "
            f"{description.world.resolution:g} m map grid)"
        )
    else:
        check = {}
        rule = "SimplePlanner (0.3 m robot + 0.2 m clearance on a 0.2 m grid)"
    if description.levels:
        # The check walks the 2D map of one floor; the waypoints of a multi-level world lie on
        # several floors joined by ramps, which it cannot follow.
        print("  (multi-level world: the waypoints' reachability is not checked in 2D)", file=out)
    else:
        for i, (start, w) in enumerate(zip(starts, waypoint_list, strict=True), 1):
            if not reachable_from(description.world, start, [w[:2]], **check)[0]:
                print(
                    f"  warning: waypoint {i} ({w[0]:.2f}, {w[1]:.2f}) looks unreachable from "
                    f"({start[0]:.2f}, {start[1]:.2f}) for {rule}",
                    file=out,
                )
    reservation = _domain_for_run(domain_id)
    domain = reservation.domain if reservation is not None else int(domain_id)
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    record = run_path / "ground_truth.json"
    playground_argv = [
        sys.executable,
        "-m",
        "easynav.playground",
        "--world",
        str(world),
        "--speed-up",
        str(speed_up),
        "--seed",
        str(seed),
        "--record",
        str(record),
    ]
    if not moving_obstacles:
        playground_argv.append("--no-obstacles")
    if scan_topics and scan_topics[0].lstrip("/") != "scan":
        # The params file is left as written: the playground's laser is remapped instead.
        playground_argv += ["--ros-args", "-r", f"scan:={scan_topics[0]}"]
        print(f"  - the playground's laser publishes on {scan_topics[0]}", file=out)
    children = [
        ChildProcess("playground", playground_argv, env, run_path / "playground.log"),
        ChildProcess("easynav", [*easynav, "run", str(derived)], env, run_path / "easynav.log"),
    ]
    print(f"  ROS domain {domain}; logs, params and ground truth in {run_path}", file=out)
    try:
        return _run(
            description,
            waypoint_list,
            children,
            domain,
            path_topic,
            record,
            speed_up,
            output_png,
            timeout,
            ready_timeout,
            out,
            waypoint_levels,
        )
    finally:
        if reservation is not None:
            reservation.release()
        print(f"  logs: {run_path}", file=out)


def _run(
    description,
    waypoint_list,
    children,
    domain,
    path_topic,
    record,
    speed_up,
    output_png,
    timeout,
    ready_timeout,
    out,
    waypoint_levels=None,
) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from easynav.core.goals.goal_client_state import GoalClientState as S
    from easynav.core.goals.goal_manager_client import GoalManagerClient
    from easynav.core.types import Header, Pose, PoseStamped
    from easynav.playground.demo.run_monitor import RunMonitor

    results = [WaypointResult(i, *w) for i, w in enumerate(waypoint_list, 1)]
    for w, level in zip(results, waypoint_levels or [], strict=False):
        w.level = level  # a multi-level world: reached on another level is not reached
    context = rclpy.Context()
    saved_range = os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE")
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    try:
        rclpy.init(context=context, domain_id=domain)
    finally:
        if saved_range is None:
            os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
        else:
            os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = saved_range
    executor = SingleThreadedExecutor(context=context)
    monitor = None
    client = None
    progress = ProgressLine(out)
    code = EXIT_FAILURE
    final_state = "NOT STARTED"
    status_message = ""
    nav_start = nav_end = math.nan
    try:
        for child in children:
            child.start()
        monitor = RunMonitor(path_topic, context=context)
        executor.add_node(monitor)
        client = GoalManagerClient(monitor)

        def spin_until(predicate, seconds: float, what: str) -> None:
            deadline = time.monotonic() + seconds
            while not predicate():
                for child in children:
                    if child.exit_code() is not None:
                        raise DemoError(
                            f"{child.name} exited with code {child.exit_code()} while {what}:\n"
                            f"{child.log_tail()}"
                        )
                if time.monotonic() > deadline:
                    raise DemoError(f"timed out after {seconds:.0f} s {what}")
                executor.spin_once(timeout_sec=SPIN_STEP)

        progress.show("waiting for the playground and EasyNav...", force=True)
        spin_until(lambda: monitor.truth is not None, ready_timeout, "waiting for the playground")
        spin_until(client.manager_available, ready_timeout, "waiting for EasyNav's goal manager")
        stamp = monitor.get_clock().now().nanoseconds * 1e-9
        goals = [
            PoseStamped(
                Header(stamp, "map"),
                Pose.from_xy_yaw(w.x, w.y, w.yaw, goal_height(description, w)),  # its floor's z
            )
            for w in results
        ]
        client.send_goals(goals)
        spin_until(
            lambda: client.get_state() is not S.SENT_GOAL,
            ready_timeout,
            "waiting for the goal manager to answer",
        )
        nav_start = monitor.truth[0]
        deadline = time.monotonic() + timeout
        while True:
            state = client.get_state()
            feedback = client.get_feedback()
            now = monitor.truth[0]
            remaining = monitor.remaining_goals
            if feedback is not None and feedback.goals.goals:
                remaining = min(
                    remaining if remaining is not None else 10**9, len(feedback.goals.goals)
                )
            if state is S.NAVIGATION_FINISHED:
                remaining = 0
            if remaining is not None:
                for w in results[: len(results) - remaining]:
                    if w.reached_at is None:
                        w.reached_at = now
            if state.is_terminal:
                result = client.get_result()
                final_state = state.name
                status_message = result.status_message if result else ""
                break
            current = next((w for w in results if not w.reached), None)
            to_go = feedback.distance_to_goal if feedback is not None else monitor.distance_to_goal
            if to_go is None and current is not None:
                to_go = math.hypot(current.x - monitor.truth[1], current.y - monitor.truth[2])
            reached = sum(w.reached for w in results)
            progress.show(
                f"[{state.name}] waypoint {min(reached + 1, len(results))} of {len(results)}"
                f"  to go {to_go if to_go is not None else float('nan'):5.2f} m"
                f"  speed {monitor.speed:4.2f} m/s  t={now - nav_start:6.1f} s"
                f"  collisions {monitor.collision_count}"
            )
            for child in children:
                if child.exit_code() is not None:
                    raise DemoError(
                        f"{child.name} exited with code {child.exit_code()}:\n{child.log_tail()}"
                    )
            if time.monotonic() > deadline:
                final_state = "TIMEOUT"
                status_message = f"no result within {timeout:.0f} s"
                client.cancel()
                break
            executor.spin_once(timeout_sec=SPIN_STEP)
        nav_end = monitor.truth[0]
    except DemoError as err:
        progress.finish()
        print(f"easynav demo: {err}", file=sys.stderr)
        final_state = "ERROR"
        status_message = str(err).splitlines()[0]
    except KeyboardInterrupt:
        progress.finish()
        print("easynav demo: interrupted", file=sys.stderr)
        final_state = "INTERRUPTED"
        code = EXIT_INTERRUPTED
        if client is not None and client.get_state().is_navigating:
            client.cancel()
    finally:
        progress.finish()
        for child in reversed(children):  # EasyNav first (it stops the robot), then the robot
            child.stop()
        executor.shutdown()
        if monitor is not None:
            monitor.destroy_node()
        rclpy.shutdown(context=context)

    try:
        truth = GroundTruthRecorder.load(record)
        data = json.loads(Path(record).read_text())
        wall = data.get("wall_time")
        rtf = data["sim_time"] / wall if wall else math.nan
    except (OSError, ValueError, KeyError) as err:
        print(f"easynav demo: no ground truth from the playground ({err})", file=sys.stderr)
        truth, rtf = GroundTruthRecorder(), math.nan
    if monitor is not None:
        truth.estimated_poses = list(monitor.estimates.estimated_poses)
    if math.isnan(nav_start):
        nav_start = truth.true_poses[0][0] if truth.true_poses else 0.0
    if math.isnan(nav_end):
        nav_end = truth.true_poses[-1][0] if truth.true_poses else nav_start
    summary = RunSummary.compute(
        results,
        truth,
        final_state,
        status_message,
        nav_start,
        nav_end,
        monitor.command_rate(nav_start, nav_end) if monitor is not None else 0.0,
        rtf,
    )
    if monitor is not None:
        summary.late_rt_cycles = monitor.late_cycles
    summary.controller_cycle = controller_cycle_from_log(Path(record).with_name("easynav.log"))
    truth.save(Path(record).with_name("run.json"))  # truth + EasyNav's estimates, for analysis
    Path(record).with_name("summary.json").write_text(json.dumps(summary.to_dict(), indent=2))
    print(summary.format_table(), file=out)
    if output_png:
        plot_run(
            output_png,
            description.world,
            results,
            description.start_pose,
            truth.true_poses,
            truth.estimated_poses,
            monitor.paths if monitor is not None else (),
            truth.collisions,
            description.make_obstacles(),
            title=f"EasyNav playground demo: {description.world.name}, "
            f"{sum(w.achieved for w in results)}/{len(results)} waypoints, "
            f"{len(truth.collisions)} collision(s), {summary.final_state}",
            terrain=description.make_terrain(),
            levels=description.make_levels(),
        )
        print(f"picture: {Path(output_png).resolve()}", file=out)
    if code == EXIT_INTERRUPTED:
        return code
    return EXIT_SUCCESS if summary.success else EXIT_FAILURE


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``easynav demo``."""
    parser = argparse.ArgumentParser(
        prog="easynav demo",
        description="Start the playground robot and EasyNav, drive through waypoints, then "
        "print a summary and draw the run.",
        epilog="Exit codes: 0 every waypoint reached without a collision, 1 not, 2 bad "
        "arguments, 130 interrupted.",
    )
    parser.add_argument(
        "--world",
        help="shipped world (home, office), a world "
        "YAML, a map-server YAML or a .map file (default: home; crossing with --robots)",
    )
    parser.add_argument(
        "--robots",
        type=int,
        default=1,
        help="number of robots (default 1); more: the world's first N 'robots', one EasyNav "
        "each in its namespace (r1, r2...) with its tf_prefix, their waypoints at once",
    )
    parser.add_argument(
        "--params", help=f"EasyNav params file (default: the playground's {DEFAULT_PARAMS.name})"
    )
    parser.add_argument("--waypoints", help="YAML list of [x, y, yaw] (default: the world's)")
    parser.add_argument(
        "--speed-up",
        type=float,
        default=1.0,
        help="simulated seconds per wall second (default 1.0)",
    )
    parser.add_argument(
        "--output",
        default="easynav_demo.png",
        help="picture of the run (default: easynav_demo.png)",
    )
    parser.add_argument(
        "--timeout",
        type=float,
        default=600.0,
        help="give up after this many wall seconds (default 600)",
    )
    parser.add_argument("--seed", type=int, default=0, help="sensor noise seed (default 0)")
    parser.add_argument(
        "--no-obstacles", action="store_true", help="leave the world's moving obstacles out"
    )
    parser.add_argument(
        "--domain-id", type=int, help="ROS domain of the run (default: from the process id)"
    )
    parser.add_argument(
        "--run-dir",
        help="directory for logs, derived params and ground truth "
        "(default: a new temporary directory)",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """``easynav demo`` / ``easynav-playground-demo``: parse options, run, return the exit code."""
    args = build_parser().parse_args(argv)
    if args.robots < 1:
        print(f"easynav demo: --robots must be >= 1, got {args.robots}", file=sys.stderr)
        return EXIT_USAGE
    if args.robots > 1:
        from easynav.playground.demo.fleet_demo import run_fleet_demo

        if args.waypoints:
            print("easynav demo: with --robots the waypoints are each robot's in the world "
                  "description (leave --waypoints out)", file=sys.stderr)
            return EXIT_USAGE
    common = dict(
        params_file=args.params,
        speed_up=args.speed_up,
        output_png=args.output,
        timeout=args.timeout,
        seed=args.seed,
        moving_obstacles=not args.no_obstacles,
        domain_id=args.domain_id,
        run_dir=args.run_dir,
    )
    if args.robots > 1:
        return run_fleet_demo(world=args.world or "crossing", robots=args.robots, **common)
    return run_demo(world=args.world or "home", waypoints=args.waypoints, **common)


def controller_cycle_from_log(log_path: Path) -> dict | None:
    """The controller's update_rt cost from the line EasyNav's controller_node logs when it
    is deactivated (the last one, if it was activated more than once); None when absent."""
    from easynav.core.system.cycle_times import DESCRIPTION_PATTERN

    try:
        text = log_path.read_text(errors="replace")
    except OSError:
        return None
    found = None
    for line in text.splitlines():
        if "controller_node" not in line:
            continue
        match = DESCRIPTION_PATTERN.search(line)
        if match and match["method"] == "update_rt":
            found = {
                "alias": match["alias"], "plugin": match["plugin"], "runs": int(match["runs"]),
                "median_ms": float(match["median"]), "p99_ms": float(match["p99"]),
                "max_ms": float(match["max"]),
            }
    return found
