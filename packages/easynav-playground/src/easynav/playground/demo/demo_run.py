"""DemoRun: one demo mission once its files are written: start, send, follow, stop, report.

The demo's run in five steps, one method each, so that a reader sees the order at a glance:

1. :meth:`DemoRun._start`: start the playground and EasyNav, wait for the robot's ground truth
   and for EasyNav's goal manager;
2. :meth:`DemoRun._send_waypoints`: send every waypoint as one goal list and wait for the
   manager's answer;
3. :meth:`DemoRun._follow`: show the progress until the navigation ends, a process dies or the
   wall-clock timeout (then the navigation is cancelled);
4. :meth:`DemoRun._stop`: stop EasyNav first (it stops the robot), then the playground;
5. :meth:`DemoRun._report`: the summary table, ``summary.json``, ``run.json``, ``paths.json``
   and the picture.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path
from typing import TextIO

from easynav.playground.demo.child_process import ChildProcess
from easynav.playground.demo.navmap_params import goal_height
from easynav.playground.demo.progress_line import ProgressLine
from easynav.playground.demo.run_plot import plot_run
from easynav.playground.demo.run_summary import RunSummary
from easynav.playground.demo.stop_signals import StopSignals
from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder

# The demo's exit codes.
EXIT_SUCCESS = 0  # every waypoint reached without a collision
EXIT_FAILURE = 1  # not (or a process died, or the timeout expired)
EXIT_USAGE = 2  # bad arguments
EXIT_INTERRUPTED = 130  # Ctrl-C

SPIN_STEP = 0.05  # s per executor wait in the main loop


class DemoError(Exception):
    """A problem that ends the demo with a message (bad input, a process that died)."""



class DemoRun:
    """One demo mission over prepared files: ``execute()`` runs it and returns the exit code.

    Args:
        description: the world (a WorldDescription).
        waypoints: ``[(x, y, yaw), ...]`` in the map frame.
        waypoint_levels: the floor of each waypoint in a multi-level world (None: one floor);
            a waypoint reached on another floor is not reached.
        children: the playground's and EasyNav's processes, not started yet.
        domain: the ROS domain of the run (the children's too).
        path_topic: where EasyNav publishes its path (drawn in the picture).
        record: the playground's ground-truth file (``run.json``, ``summary.json``,
            ``paths.json`` and ``easynav.log`` lie beside it).
        output_png: the picture of the run (None: none).
        timeout: wall seconds of navigation before the run is cancelled.
        ready_timeout: wall seconds to wait for the playground, the goal manager and its answer.
        out: where the progress and the summary are printed.
        estimate_topic: where the localizer publishes its pose when TF does not carry it
            (None: EasyNav's estimate is read from TF).
        stop_at_collision: end the mission (cancel the navigation) at the first collision.

    Thread contract: main thread only; ``execute()`` once. A Ctrl-C during the run cancels the
    navigation, stops the processes and reports (exit code 130).
    """

    def __init__(
        self,
        description,
        waypoints: list[tuple[float, float, float]],
        waypoint_levels: list[int] | None,
        children: list[ChildProcess],
        domain: int,
        path_topic: str,
        record: Path,
        output_png: str | Path | None,
        timeout: float,
        ready_timeout: float,
        out: TextIO,
        estimate_topic: str | None = None,
        stop_at_collision: bool = False,
    ) -> None:
        self.description = description
        self.results = [WaypointResult(i, *w) for i, w in enumerate(waypoints, 1)]
        for w, level in zip(self.results, waypoint_levels or [], strict=False):
            w.level = level
        self.children = children
        self.domain = domain
        self.path_topic = path_topic
        self.record = Path(record)
        self.output_png = output_png
        self.timeout = timeout
        self.ready_timeout = ready_timeout
        self.out = out
        self.estimate_topic = estimate_topic
        self.stop_at_collision = stop_at_collision
        self.progress = ProgressLine(out)
        self.context = None
        self.executor = None
        self.monitor = None
        self.client = None
        self.code = EXIT_FAILURE
        self.final_state = "NOT STARTED"
        self.status_message = ""
        self.nav_start = math.nan
        self.nav_end = math.nan
        self._stop_signals = StopSignals()

    # ------------------------------------------------------------------ the run
    def execute(self) -> int:
        """Run the mission and report; returns the demo's exit code."""
        self._open_ros()
        try:
            with self._stop_signals:
                self._start()
                self._send_waypoints()
                self._follow()
        except DemoError as err:
            self.progress.finish()
            print(f"easynav demo: {err}", file=sys.stderr)
            self.final_state = "ERROR"
            self.status_message = str(err).splitlines()[0]
        except KeyboardInterrupt:
            self.progress.finish()
            print("easynav demo: interrupted", file=sys.stderr)
            self.final_state = "INTERRUPTED"
            self.code = EXIT_INTERRUPTED
            if self.client is not None and self.client.get_state().is_navigating:
                self.client.cancel()
        finally:
            self._stop()
        return self._report()

    def _open_ros(self) -> None:
        import rclpy

        from easynav.system.executor import make_executor

        self.context = rclpy.Context()
        # This process's participant discovers on this host only, like its children's.
        saved_range = os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE")
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        try:
            rclpy.init(context=self.context, domain_id=self.domain)
        finally:
            if saved_range is None:
                os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
            else:
                os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = saved_range
        self.executor = make_executor(self.context)

    def _start(self) -> None:
        from easynav.playground.demo.run_monitor import RunMonitor
        from easynav.system.goals.goal_manager_client import GoalManagerClient

        for child in self.children:
            child.start()
        self.monitor = RunMonitor(
            self.path_topic, estimate_topic=self.estimate_topic, context=self.context
        )
        self.executor.add_node(self.monitor)
        self.client = GoalManagerClient(self.monitor)
        self.progress.show("waiting for the playground and EasyNav...", force=True)
        self._spin_until(
            lambda: self.monitor.truth is not None, self.ready_timeout,
            "waiting for the playground",
        )
        self._spin_until(
            self.client.manager_available, self.ready_timeout,
            "waiting for EasyNav's goal manager",
        )

    def _send_waypoints(self) -> None:
        from easynav.core.types import Header, Pose, PoseStamped
        from easynav.system.goals.goal_client_state import GoalClientState

        stamp = self.monitor.get_clock().now().nanoseconds * 1e-9
        goals = [
            PoseStamped(
                Header(stamp, "map"),
                Pose.from_xy_yaw(w.x, w.y, w.yaw, goal_height(self.description, w)),  # its floor
            )
            for w in self.results
        ]
        self.client.send_goals(goals)
        self._spin_until(
            lambda: self.client.get_state() is not GoalClientState.SENT_GOAL,
            self.ready_timeout,
            "waiting for the goal manager to answer",
        )

    def _follow(self) -> None:
        client, monitor = self.client, self.monitor
        self.nav_start = monitor.truth[0]
        deadline = time.monotonic() + self.timeout
        while True:
            state = client.get_state()
            feedback = client.get_feedback()
            self._mark_reached(state, feedback)
            if state.is_terminal:
                result = client.get_result()
                self.final_state = state.name
                self.status_message = result.status_message if result else ""
                break
            self._show_progress(state, feedback)
            self._check_children("")
            if time.monotonic() > deadline:
                self.final_state = "TIMEOUT"
                self.status_message = f"no result within {self.timeout:.0f} s"
                client.cancel()
                break
            if self.stop_at_collision and monitor.collision_count:
                self.final_state = "COLLISION"
                self.status_message = "stopped at the first collision"
                client.cancel()
                break
            self._spin()
        self.nav_end = monitor.truth[0]

    def _mark_reached(self, state, feedback) -> None:
        """Stamp the waypoints the goal manager no longer lists as reached: when the goal
        manager said so (its feedback's stamp, EasyNav's simulated clock), else the newest
        true time this process has seen.

        Not when this process got round to reading it: under load its feedback queue ran 16 s
        behind the live truth, and a waypoint of the upper floor was scored where the robot
        then was, on the ramp 4 m away (the two-floors run failed on it).
        """
        from easynav.system.goals.goal_client_state import GoalClientState

        now = self.monitor.truth[0]

        def stamp_of(message) -> float:  # a NavigationControl's stamp (s), clamped to now
            stamp = float(message.header.stamp) if message is not None else 0.0
            return stamp if 0.0 < stamp < now else now

        if state is GoalClientState.NAVIGATION_FINISHED:
            remaining, said_at = 0, stamp_of(self.client.get_result())
        elif feedback is not None and feedback.goals.goals:
            remaining, said_at = len(feedback.goals.goals), stamp_of(feedback)
        else:  # no feedback yet: the goal manager's info topic (unstamped)
            remaining, said_at = self.monitor.remaining_goals, now
        if remaining is not None:
            for w in self.results[: len(self.results) - remaining]:
                if w.reached_at is None:
                    w.reached_at = said_at

    def _show_progress(self, state, feedback) -> None:
        monitor, results = self.monitor, self.results
        current = next((w for w in results if not w.reached), None)
        to_go = feedback.distance_to_goal if feedback is not None else monitor.distance_to_goal
        if to_go is None and current is not None:
            to_go = math.hypot(current.x - monitor.truth[1], current.y - monitor.truth[2])
        reached = sum(w.reached for w in results)
        self.progress.show(
            f"[{state.name}] waypoint {min(reached + 1, len(results))} of {len(results)}"
            f"  to go {to_go if to_go is not None else float('nan'):5.2f} m"
            f"  speed {monitor.speed:4.2f} m/s  t={monitor.truth[0] - self.nav_start:6.1f} s"
            f"  collisions {monitor.collision_count}"
        )

    def _stop(self) -> None:
        import rclpy

        self.progress.finish()
        for child in reversed(self.children):  # EasyNav first (it stops the robot)
            child.stop()
        self.executor.shutdown()
        if self.monitor is not None:
            self.monitor.destroy_node()
        rclpy.shutdown(context=self.context)

    # ------------------------------------------------------------------ waiting
    def _check_children(self, what: str) -> None:
        for child in self.children:
            if child.exit_code() is not None:
                raise DemoError(
                    f"{child.name} exited with code {child.exit_code()}{what}:\n"
                    f"{child.log_tail()}"
                )

    def _spin_until(self, predicate, seconds: float, what: str) -> None:
        deadline = time.monotonic() + seconds
        while not predicate():
            self._check_children(f" while {what}")
            if time.monotonic() > deadline:
                raise DemoError(f"timed out after {seconds:.0f} s {what}")
            self._spin()

    def _spin(self) -> None:
        """One wait of the executor; then a Ctrl-C or SIGTERM that arrived ends the run, raised
        here rather than inside a callback of the EventsExecutor (see StopSignals)."""
        self.executor.spin_once(timeout_sec=SPIN_STEP)
        self._stop_signals.check()

    # ------------------------------------------------------------------ the report
    def _report(self) -> int:
        truth, rtf = self._load_truth()
        monitor = self.monitor
        if monitor is not None:
            truth.estimated_poses = list(monitor.estimates.estimated_poses)
        if math.isnan(self.nav_start):
            self.nav_start = truth.true_poses[0][0] if truth.true_poses else 0.0
        if math.isnan(self.nav_end):
            self.nav_end = truth.true_poses[-1][0] if truth.true_poses else self.nav_start
        summary = RunSummary.compute(
            self.results,
            truth,
            self.final_state,
            self.status_message,
            self.nav_start,
            self.nav_end,
            monitor.command_rate(self.nav_start, self.nav_end) if monitor is not None else 0.0,
            rtf,
        )
        if monitor is not None:
            summary.late_rt_cycles = monitor.late_cycles
        summary.controller_cycle = controller_cycle_from_log(self.record.with_name("easynav.log"))
        summary.odometry_age = odometry_age_from_log(self.record.with_name("easynav.log"))
        truth.save(self.record.with_name("run.json"))  # truth + EasyNav's estimates
        if monitor is not None:
            self.record.with_name("paths.json").write_text(json.dumps(monitor.paths_record()))
        self.record.with_name("summary.json").write_text(
            json.dumps(summary.to_dict(), indent=2)
        )
        print(summary.format_table(), file=self.out)
        if self.output_png:
            self._draw(truth, summary)
        if self.code == EXIT_INTERRUPTED:
            return self.code
        return EXIT_SUCCESS if summary.success else EXIT_FAILURE

    def _load_truth(self) -> tuple[GroundTruthRecorder, float]:
        """The playground's record and the real-time factor it reached (NaN when unknown)."""
        try:
            truth = GroundTruthRecorder.load(self.record)
            data = json.loads(self.record.read_text())
            wall = data.get("wall_time")
            return truth, (data["sim_time"] / wall if wall else math.nan)
        except (OSError, ValueError, KeyError) as err:
            print(f"easynav demo: no ground truth from the playground ({err})", file=sys.stderr)
            return GroundTruthRecorder(), math.nan

    def _draw(self, truth: GroundTruthRecorder, summary: RunSummary) -> None:
        description, results = self.description, self.results
        plot_run(
            self.output_png,
            description.world,
            results,
            description.start_pose,
            truth.true_poses,
            truth.estimated_poses,
            self.monitor.paths if self.monitor is not None else (),
            truth.collisions,
            description.make_obstacles(),
            title=f"EasyNav playground demo: {description.world.name}, "
            f"{sum(w.achieved for w in results)}/{len(results)} waypoints, "
            f"{len(truth.collisions)} collision(s), {summary.final_state}",
            terrain=description.make_terrain(),
            levels=description.make_levels(),
        )
        print(f"picture: {Path(self.output_png).resolve()}", file=self.out)


def controller_cycle_from_log(log_path: Path) -> dict | None:
    """The controller's update_rt cost from the line EasyNav's controller_node logs when it
    is deactivated (the last one, if it was activated more than once); None when absent."""
    from easynav.system.cycle_times import DESCRIPTION_PATTERN

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


def odometry_age_from_log(log_path: Path) -> dict | None:
    """How old the ``odom → robot`` transforms were when EasyNav's TF listener served them, from
    the line system_node logs when it is deactivated (the last one): ``{"transforms",
    "median_ms", "p99_ms", "max_ms"}``; None when absent."""
    from easynav.system.tf.tf_listener import ODOMETRY_AGE_PATTERN

    try:
        text = log_path.read_text(errors="replace")
    except OSError:
        return None
    found = None
    for match in ODOMETRY_AGE_PATTERN.finditer(text):
        found = {
            "transforms": int(match["count"]), "median_ms": float(match["median"]),
            "p99_ms": float(match["p99"]), "max_ms": float(match["max"]),
        }
    return found
