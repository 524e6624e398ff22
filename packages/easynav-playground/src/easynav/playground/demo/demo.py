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
import math
import os
import shutil
import sys
import tempfile
from importlib import resources
from pathlib import Path
from typing import TextIO

from easynav.playground.demo.child_process import ChildProcess
from easynav.playground.demo.demo_run import (  # noqa: F401 (exit codes: part of this API)
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_SUCCESS,
    EXIT_USAGE,
    DemoError,
    DemoRun,
    controller_cycle_from_log,
)
from easynav.playground.demo.navmap_params import point_navmap_stack_at_world
from easynav.playground.demo.params_patch import (
    derive_params,
    laser_scan_topics,
    planner_plugins,
    pose_estimate_topic,
)
from easynav.playground.reachability import reachable_from
from easynav.playground.world_description import (
    WorldDescription,
    load_waypoint_levels,
    load_waypoints,
)

DEFAULT_PARAMS = Path(
    str(resources.files("easynav.playground") / "params" / "playground.params.yaml")
)
COSTMAP_PLANNER = "easynav_costmap_planner/CostmapPlanner"


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
    from easynav.system.testing.dds_isolation import DomainReservation

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
    stop_at_collision: bool = False,
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
        stop_at_collision: end the mission at the playground's first collision (the
            navigation is cancelled; a scenario that shows a contact need not wait for the
            timeout).
        stream: where progress and the summary are printed (default stdout).

    Thread contract: call from the main thread (it installs nothing global but runs an
    executor and child processes until it returns).
    """
    out = stream or sys.stdout
    try:
        if not (math.isfinite(speed_up) and speed_up > 0):
            raise DemoError(f"speed-up must be > 0, got {speed_up}")
        description = WorldDescription.resolve(str(world))
        waypoint_list, waypoint_levels = _waypoints_for(description, world, waypoints)
        params_path = Path(params_file) if params_file else DEFAULT_PARAMS
        run_path = Path(run_dir) if run_dir else Path(tempfile.mkdtemp(prefix="easynav_demo_"))
        run_path.mkdir(parents=True, exist_ok=True)
        derived, notes, path_topic = _derive_run_params(description, params_path, run_path)
        costmap_planning = COSTMAP_PLANNER in planner_plugins(params_path)
        estimate_topic = pose_estimate_topic(params_path)
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
    _warn_unreachable_waypoints(description, waypoint_list, costmap_planning, out)
    reservation = _domain_for_run(domain_id)
    domain = reservation.domain if reservation is not None else int(domain_id)
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    record = run_path / "ground_truth.json"
    playground_argv = [
        sys.executable, "-m", "easynav.playground", "--world", str(world),
        "--speed-up", str(speed_up), "--seed", str(seed), "--record", str(record),
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
        return DemoRun(
            description, waypoint_list, waypoint_levels, children, domain, path_topic, record,
            output_png, timeout, ready_timeout, out, estimate_topic=estimate_topic,
            stop_at_collision=stop_at_collision,
        ).execute()
    finally:
        if reservation is not None:
            reservation.release()
        print(f"  logs: {run_path}", file=out)


def _waypoints_for(description: WorldDescription, world: str, waypoints):
    """``(waypoints, levels)``: the given list or YAML file, else the world's own; ``levels``
    (the floor of each waypoint) only from a YAML file that has them."""
    if waypoints is None:
        if description.waypoints_path is None:
            raise DemoError(f"world {world!r} has no default waypoints: pass --waypoints")
        waypoints = description.waypoints_path
    if isinstance(waypoints, str | Path):
        return load_waypoints(waypoints), load_waypoint_levels(waypoints)
    return [tuple(float(v) for v in w) for w in waypoints], None


def _derive_run_params(description: WorldDescription, params_path: Path, run_path: Path):
    """The params file pointed at the world, written to ``run_path/params.yaml``: the map (the
    world saved as a ``.map``, and as a map-server YAML for the costmap stack), the start pose,
    the robot's size and terrain, and the NavMap stack's files. Returns ``(derived params
    path, notes saying what was changed, the planner's path topic)``."""
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
        elevation_file=description.elevation_map(run_path),
    )
    notes = point_navmap_stack_at_world(
        derived, description, description.map_server_yaml(run_path), notes
    )
    return derived, notes, path_topic


def _warn_unreachable_waypoints(description: WorldDescription, waypoint_list,
                                costmap_planning: bool, out: TextIO) -> None:
    """Print a warning for each waypoint that looks unreachable from the one before (from the
    start for the first), by the rule of the planner (CostmapPlanner or SimplePlanner). The
    mission still runs: the check is a coarse grid search, the planner decides."""
    if description.levels:
        # The check walks the 2D map of one floor; the waypoints of a multi-level world lie on
        # several floors joined by ramps, which it cannot follow.
        print("  (multi-level world: the waypoints' reachability is not checked in 2D)", file=out)
        return
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
    starts = [description.start_pose[:2]] + [w[:2] for w in waypoint_list[:-1]]
    for i, (start, w) in enumerate(zip(starts, waypoint_list, strict=True), 1):
        if not reachable_from(description.world, start, [w[:2]], **check)[0]:
            print(
                f"  warning: waypoint {i} ({w[0]:.2f}, {w[1]:.2f}) looks unreachable from "
                f"({start[0]:.2f}, {start[1]:.2f}) for {rule}",
                file=out,
            )


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
