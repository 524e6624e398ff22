"""The playground demo with several robots: ``easynav demo --robots N``.

One playground process simulates the world's first N ``robots`` (each sees the others in its
laser); one ``easynav run`` per robot, in its namespace (``--ros-args -r __ns:=/r1``, as the
original runs ``system_main``) with ``system_node.tf_prefix`` = its name, all from one params
file with per-robot sections (``r1/controller_node:``...) derived from a single-robot file.
This process sends each robot its waypoints at once through a goal client in the robot's
namespace, shows the progress, and watches that the robots' topics stay apart: the publishers
of each robot's ``cmd_vel``, ``easynav_control`` and ``tf`` (sampled from the ROS graph about
once a second) are that robot's nodes (and the playground, for ``tf``), and every frame on a
robot's ``tf`` carries its prefix. Then it stops everything, prints a summary per robot and
draws one picture per robot.

Exit codes: 0 every robot reached every waypoint without a collision and no topic crossed;
1 otherwise (or a process died, or the timeout expired); 2 bad arguments; 130 interrupted.
"""

from __future__ import annotations

import json
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from easynav.playground.demo.child_process import ChildProcess
from easynav.playground.demo.demo_run import (
    EXIT_FAILURE,
    EXIT_INTERRUPTED,
    EXIT_SUCCESS,
    EXIT_USAGE,
    SPIN_STEP,
)
from easynav.playground.demo.params_patch import derive_fleet_params, laser_scan_topics
from easynav.playground.demo.progress_line import ProgressLine
from easynav.playground.demo.run_plot import plot_run
from easynav.playground.demo.run_summary import RunSummary
from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.world_description import WorldDescription, load_waypoints

GRAPH_PERIOD = 1.0  # wall s between two looks at the ROS graph
#: A robot's topics whose publishers must all be its own nodes (``tf``: and the playground).
WATCHED_TOPICS = ("cmd_vel", "easynav_control", "tf")
PLAYGROUND_NODE = ("/", "playground")
#: The node name rmw gives a publisher whose node it does not know (yet).
UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"


class FleetDemoError(Exception):
    """A problem that ends the demo with a message (bad input, a process that died)."""


@dataclass
class RobotRun:
    """One robot of the fleet demo: its waypoints, monitor, goal client and outcome."""

    name: str
    start_pose: tuple[float, float, float]
    waypoints: list[WaypointResult]
    path_topic: str | None = None
    monitor: Any = None
    client: Any = None
    final_state: str = "NOT STARTED"
    status_message: str = ""
    nav_start: float = math.nan
    nav_end: float = math.nan
    summary: RunSummary | None = None
    done: bool = False


@dataclass
class TopicWatch:
    """What the demo saw of the robots' topics: publishers out of place, foreign frames."""

    samples: int = 0
    #: Publishers seen whose node the middleware did not know at that look (not attributable).
    unattributed: int = 0
    crossings: list[str] = field(default_factory=list)
    foreign_frames: dict[str, list[str]] = field(default_factory=dict)

    @property
    def apart(self) -> bool:
        """No topic crossed and at least one look at the graph."""
        return self.samples > 0 and not self.crossings and not any(self.foreign_frames.values())

    def look(self, node, names: list[str]) -> None:
        """One look at the graph: each robot's watched topics, published by whom."""
        self.samples += 1
        for name in names:
            for topic in WATCHED_TOPICS:
                full = f"/{name}/{topic}"
                for info in node.get_publishers_info_by_topic(full):
                    where = (info.node_namespace, info.node_name)
                    if info.node_namespace == f"/{name}":
                        continue
                    if info.node_name == UNKNOWN_NODE:
                        # The middleware knows the publisher but not yet (or no longer) its
                        # node: the node list of a process travels apart from its endpoints,
                        # so a look while a node starts or stops sees this. Not attributable;
                        # the next looks name the node.
                        self.unattributed += 1
                        continue
                    if topic == "tf" and where == PLAYGROUND_NODE:
                        continue
                    crossing = f"{full} published by {info.node_namespace.rstrip('/')}/" \
                               f"{info.node_name}"
                    if crossing not in self.crossings:
                        self.crossings.append(crossing)

    def to_dict(self) -> dict:
        return {
            "graph_samples": self.samples,
            "unattributed_publishers": self.unattributed,
            "crossings": list(self.crossings),
            "foreign_frames": {k: list(v) for k, v in self.foreign_frames.items()},
            "apart": self.apart,
        }


def _easynav_command() -> list[str]:
    from easynav.playground.demo.demo import DemoError, _easynav_command

    try:
        return _easynav_command()
    except DemoError as err:
        raise FleetDemoError(str(err)) from err


def run_fleet_demo(
    world: str = "crossing",
    robots: int = 2,
    params_file: str | Path | None = None,
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
    """Run the fleet demo; returns the exit code (see the module documentation).

    Args:
        world: a world whose description declares at least ``robots`` ``robots`` (each with
            its waypoints), by name or path.
        robots: how many (>= 2).
        params_file: a single-robot EasyNav params file (default: the playground's); each
            robot's sections are derived from it (:func:`derive_fleet_params`).
        output_png: the pictures are ``<stem>_<robot><suffix>`` (None: no picture).
        Others: as :func:`~easynav.playground.demo.demo.run_demo`.

    Thread contract: call from the main thread.
    """
    from easynav.playground.demo.demo import DEFAULT_PARAMS, _domain_for_run

    out = stream or sys.stdout
    try:
        description = WorldDescription.resolve(str(world))
        entries = description.fleet(int(robots))
        runs = []
        for entry in entries:
            if entry.waypoints_path is None:
                raise FleetDemoError(f"world {world!r}: robot {entry.name} has no waypoints")
            waypoints = load_waypoints(entry.waypoints_path)
            runs.append(RobotRun(entry.name, entry.start_pose,
                                 [WaypointResult(i, *w) for i, w in enumerate(waypoints, 1)]))
        if not (math.isfinite(speed_up) and speed_up > 0):
            raise FleetDemoError(f"speed-up must be > 0, got {speed_up}")
        params_path = Path(params_file) if params_file else DEFAULT_PARAMS
        run_path = Path(run_dir) if run_dir else Path(tempfile.mkdtemp(prefix="easynav_fleet_"))
        run_path.mkdir(parents=True, exist_ok=True)
        map_file = run_path / "world.map"
        description.world.save_map_file(map_file)
        robot = description.robot
        derived = run_path / "params.yaml"
        notes, path_topics = derive_fleet_params(
            params_path,
            map_file,
            [(r.name, r.start_pose) for r in runs],
            derived,
            map_yaml=description.map_server_yaml(run_path),
            robot_radius=robot.radius if robot.declared else None,
            robot_height=robot.height,
            elevation_file=description.elevation_map(run_path),
        )
        for r in runs:
            r.path_topic = path_topics[r.name]
        scan_topics = laser_scan_topics(params_path)
        easynav = _easynav_command()
    except (OSError, ValueError, FleetDemoError) as err:
        print(f"easynav demo: {err}", file=sys.stderr)
        return EXIT_USAGE

    print(
        f"EasyNav playground demo: world '{description.world.name}', {len(runs)} robots ("
        + ", ".join(f"{r.name}: {len(r.waypoints)} waypoint(s)" for r in runs)
        + f"), speed-up x{speed_up:g}",
        file=out,
    )
    print(f"  params: {params_path}, one section per robot in {derived}", file=out)
    for note in notes:
        print(f"  - {note}", file=out)
    reservation = _domain_for_run(domain_id)
    domain = reservation.domain if reservation is not None else int(domain_id)
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    record = run_path / "ground_truth.json"
    playground_argv = [
        sys.executable, "-m", "easynav.playground", "--world", str(world),
        "--robots", str(len(runs)), "--speed-up", str(speed_up), "--seed", str(seed),
        "--record", str(record),
    ]
    if not moving_obstacles:
        playground_argv.append("--no-obstacles")
    laser = scan_topics[0].lstrip("/") if scan_topics else "scan"
    if laser != "scan":
        playground_argv.append("--ros-args")
        for r in runs:
            playground_argv += ["-r", f"/{r.name}/scan:=/{r.name}/{laser}"]
        print(f"  - the playground's lasers publish on <robot>/{laser}", file=out)
    children = [ChildProcess("playground", playground_argv, env, run_path / "playground.log")]
    for r in runs:
        children.append(
            ChildProcess(
                f"easynav {r.name}",
                [*easynav, "run", str(derived), "--ros-args", "-r", f"__ns:=/{r.name}"],
                env,
                run_path / f"easynav_{r.name}.log",
            )
        )
    print(f"  ROS domain {domain}; logs, params and ground truth in {run_path}", file=out)
    try:
        return _run(description, runs, children, domain, record, output_png, timeout,
                    ready_timeout, out)
    finally:
        if reservation is not None:
            reservation.release()
        print(f"  logs: {run_path}", file=out)


def _run(description, runs, children, domain, record, output_png, timeout, ready_timeout,
         out) -> int:
    import rclpy

    from easynav.core.types import Header, Pose, PoseStamped
    from easynav.playground.demo.run_monitor import RunMonitor
    from easynav.playground.demo.stop_signals import StopSignals
    from easynav.system.executor import make_executor
    from easynav.system.goals.goal_client_state import GoalClientState as S
    from easynav.system.goals.goal_manager_client import GoalManagerClient

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
    executor = make_executor(context)
    progress = ProgressLine(out)
    watch = TopicWatch()
    names = [r.name for r in runs]
    code = EXIT_FAILURE
    # Ctrl-C / SIGTERM raised after a spin, not inside the EventsExecutor's callbacks.
    stop = StopSignals().__enter__()
    try:
        for child in children:
            child.start()
        for r in runs:
            r.monitor = RunMonitor(r.path_topic, frame_prefix=r.name, namespace=r.name,
                                   context=context)
            executor.add_node(r.monitor)
            r.client = GoalManagerClient(r.monitor)

        def check_children(what: str) -> None:
            for child in children:
                if child.exit_code() is not None:
                    raise FleetDemoError(
                        f"{child.name} exited with code {child.exit_code()} {what}:\n"
                        f"{child.log_tail()}"
                    )

        def spin_until(predicate, seconds: float, what: str) -> None:
            deadline = time.monotonic() + seconds
            while not predicate():
                check_children(f"while {what}")
                if time.monotonic() > deadline:
                    raise FleetDemoError(f"timed out after {seconds:.0f} s {what}")
                executor.spin_once(timeout_sec=SPIN_STEP)
                stop.check()

        progress.show("waiting for the playground and the EasyNav instances...", force=True)
        spin_until(lambda: all(r.monitor.truth is not None for r in runs), ready_timeout,
                   "waiting for the playground")
        spin_until(lambda: all(r.client.manager_available() for r in runs), ready_timeout,
                   "waiting for the goal managers")
        for r in runs:
            stamp = r.monitor.get_clock().now().nanoseconds * 1e-9
            r.client.send_goals([
                PoseStamped(Header(stamp, f"{r.name}/map"), Pose.from_xy_yaw(w.x, w.y, w.yaw))
                for w in r.waypoints
            ])
        spin_until(lambda: all(r.client.get_state() is not S.SENT_GOAL for r in runs),
                   ready_timeout, "waiting for the goal managers to answer")
        for r in runs:
            r.nav_start = r.monitor.truth[0]
        deadline = time.monotonic() + timeout
        next_look = 0.0
        while not all(r.done for r in runs):
            if time.monotonic() >= next_look:
                next_look = time.monotonic() + GRAPH_PERIOD
                watch.look(runs[0].monitor, names)
            parts = []
            for r in runs:
                if not r.done:
                    _follow(r, S)
                reached = sum(w.reached for w in r.waypoints)
                parts.append(
                    f"{r.name} [{r.final_state if r.done else r.client.get_state().name}] "
                    f"{reached}/{len(r.waypoints)}"
                )
            progress.show("  ".join(parts) + f"  t={runs[0].monitor.truth[0]:6.1f} s")
            check_children("during the run")
            if time.monotonic() > deadline:
                for r in runs:
                    if not r.done:
                        r.final_state = "TIMEOUT"
                        r.status_message = f"no result within {timeout:.0f} s"
                        r.done = True
                        r.nav_end = r.monitor.truth[0]
                        r.client.cancel()
                break
            executor.spin_once(timeout_sec=SPIN_STEP)
            stop.check()
        watch.look(runs[0].monitor, names)
    except FleetDemoError as err:
        progress.finish()
        print(f"easynav demo: {err}", file=sys.stderr)
        for r in runs:
            if not r.done:
                r.final_state, r.status_message = "ERROR", str(err).splitlines()[0]
    except KeyboardInterrupt:
        progress.finish()
        print("easynav demo: interrupted", file=sys.stderr)
        code = EXIT_INTERRUPTED
        for r in runs:
            if not r.done:
                r.final_state = "INTERRUPTED"
                if r.client is not None and r.client.get_state().is_navigating:
                    r.client.cancel()
    finally:
        stop.__exit__(None, None, None)
        progress.finish()
        for child in reversed(children):  # the EasyNav instances first, then the robots
            child.stop()
        for r in runs:
            if r.monitor is not None:
                with r.monitor.lock:
                    watch.foreign_frames[r.name] = sorted(r.monitor.foreign_frames)
        executor.shutdown()
        for r in runs:
            if r.monitor is not None:
                r.monitor.destroy_node()
        rclpy.shutdown(context=context)
    return _report(description, runs, watch, record, output_png, code, out)


def _follow(r: RobotRun, S) -> None:
    """Update one robot's waypoints and end state from its goal client and monitor."""
    state = r.client.get_state()
    feedback = r.client.get_feedback()
    now = r.monitor.truth[0]
    remaining = r.monitor.remaining_goals
    if feedback is not None and feedback.goals.goals:
        remaining = min(remaining if remaining is not None else 10**9, len(feedback.goals.goals))
    if state is S.NAVIGATION_FINISHED:
        remaining = 0
    if remaining is not None:
        for w in r.waypoints[: len(r.waypoints) - remaining]:
            if w.reached_at is None:
                w.reached_at = now
    if state.is_terminal:
        result = r.client.get_result()
        r.final_state = state.name
        r.status_message = result.status_message if result else ""
        r.nav_end = now
        r.done = True


def _report(description, runs, watch, record, output_png, code, out) -> int:
    """Summaries, the fleet file and the pictures; returns the exit code."""
    try:
        data = json.loads(Path(record).read_text())
        per_robot = data["robots"]
        wall = data.get("wall_time")
        rtf = data["sim_time"] / wall if wall else math.nan
    except (OSError, ValueError, KeyError) as err:
        print(f"easynav demo: no ground truth from the playground ({err})", file=sys.stderr)
        per_robot, rtf = {}, math.nan
    success = True
    fleet = {"world": description.world.name, "robots": {}, "topics": watch.to_dict()}
    for r in runs:
        truth = GroundTruthRecorder()
        robot_data = per_robot.get(r.name)
        if robot_data is not None:
            path = Path(record).with_name(f"ground_truth_{r.name}.json")
            path.write_text(json.dumps(robot_data))
            truth = GroundTruthRecorder.load(path)
        if r.monitor is not None:
            truth.estimated_poses = list(r.monitor.estimates.estimated_poses)
        nav_start = r.nav_start if not math.isnan(r.nav_start) else (
            truth.true_poses[0][0] if truth.true_poses else 0.0)
        nav_end = r.nav_end if not math.isnan(r.nav_end) else (
            truth.true_poses[-1][0] if truth.true_poses else nav_start)
        r.summary = RunSummary.compute(
            r.waypoints, truth, r.final_state, r.status_message, nav_start, nav_end,
            r.monitor.command_rate(nav_start, nav_end) if r.monitor is not None else 0.0, rtf,
        )
        success = success and r.summary.success
        fleet["robots"][r.name] = r.summary.to_dict()
        print(f"robot {r.name}:", file=out)
        print(r.summary.format_table(), file=out)
        if output_png:
            png = Path(output_png)
            png = png.with_name(f"{png.stem}_{r.name}{png.suffix or '.png'}")
            plot_run(
                png, description.world, r.waypoints, r.start_pose, truth.true_poses,
                truth.estimated_poses, r.monitor.paths if r.monitor is not None else (),
                truth.collisions, description.make_obstacles(),
                title=f"EasyNav playground demo: {description.world.name}, robot {r.name}, "
                f"{sum(w.reached for w in r.waypoints)}/{len(r.waypoints)} waypoints, "
                f"{len(truth.collisions)} collision(s), {r.summary.final_state}",
                terrain=description.make_terrain(),
            )
            print(f"picture: {png.resolve()}", file=out)
    if watch.apart:
        print(f"topics apart: every publisher of each robot's {', '.join(WATCHED_TOPICS)} in its "
              f"namespace ({watch.samples} looks at the graph), every frame on its tf prefixed",
              file=out)
    else:
        print("topics crossed: " + "; ".join(
            watch.crossings + [f"{name}/tf carried {frames}"
                               for name, frames in watch.foreign_frames.items() if frames]
        ) + ("" if watch.samples else "no look at the graph"), file=out)
    Path(record).with_name("fleet.json").write_text(json.dumps(fleet, indent=2))
    if code == EXIT_INTERRUPTED:
        return code
    return EXIT_SUCCESS if success and watch.apart else EXIT_FAILURE
