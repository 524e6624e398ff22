"""ScenarioRun: the playground (and, optionally, ``easynav run``) in subprocesses, watched and
driven from the test process; the orchestration of the playground demo, reused.
"""

from __future__ import annotations

import copy
import json
import math
import os
import shutil
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

from easynav.playground.demo.child_process import ChildProcess
from easynav.playground.demo.demo import DEFAULT_PARAMS as PLAYGROUND_PARAMS
from easynav.playground.demo.params_patch import derive_params
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.world_description import WORLDS_DIR, WorldDescription

REPO = Path(__file__).resolve().parents[2]
#: The diagnostic recovery example of easynav-recovery (no costmap: fits the simple stack).
DIAGNOSTIC_RECOVERY_PARAMS = (
    REPO / "packages" / "easynav-recovery" / "params" / "diagnostic_recovery.params.yaml"
)
HOME_MAP = WORLDS_DIR / "home.map"
SPIN_STEP = 0.02  # s per executor wait while waiting for something


def speed_up() -> float:
    """Simulated seconds per wall second of the scenarios: ``EASYNAV_SCENARIO_SPEED_UP``
    (default 2.0; 1.0 on a machine too busy to keep EasyNav's rates at 2x).
    """
    return float(os.environ.get("EASYNAV_SCENARIO_SPEED_UP", "2.0"))


class ScenarioError(AssertionError):
    """A scenario could not run as intended (a process died, a wait timed out)."""


#: EasyNav's side of the command watchdog: the command is republished at least every 0.1 s (wall
#: clock), so a base watchdog can tell a constant command from a silent EasyNav.
SCENARIO_OVERRIDES: dict[str, Any] = {"controller_node.cmd_vel_keepalive_period": 0.1}
#: The robot's side: the base brakes when no command came for 0.5 s (simulated), as real drivers
#: do. On a starved machine EasyNav can stall for a second; without it the base would drive on.
PLAYGROUND_PARAMETERS: dict[str, Any] = {"cmd_timeout": 0.5}


def scenario_params(recovery: Path | None = DIAGNOSTIC_RECOVERY_PARAMS, **overrides: Any) -> dict:
    """The playground's params document (simple stack) with the ``recovery_node`` block of
    ``recovery`` (None: keep the playground's, no recovery), then :data:`SCENARIO_OVERRIDES`
    and ``overrides``: dotted paths ``"node.a.b"`` under ``ros__parameters`` (``None`` removes
    the key).
    """
    document = yaml.safe_load(PLAYGROUND_PARAMS.read_text())
    if recovery is not None:
        document["recovery_node"] = yaml.safe_load(Path(recovery).read_text())["recovery_node"]
    document = copy.deepcopy(document)
    for path, value in {**SCENARIO_OVERRIDES, **overrides}.items():
        node, *keys = path.split(".")
        target = document.setdefault(node, {}).setdefault("ros__parameters", {})
        for key in keys[:-1]:
            target = target.setdefault(key, {})
        if value is None:
            target.pop(keys[-1], None)
        else:
            target[keys[-1]] = value
    return document


def world_file(
    directory: Path,
    name: str,
    start_pose: tuple[float, float, float],
    obstacles: list[dict] | None = None,
) -> Path:
    """Write a world description on the home map with its own start pose and obstacles."""
    path = Path(directory) / f"{name}.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "map": str(HOME_MAP),
                "start_pose": [float(v) for v in start_pose],
                "moving_obstacles": obstacles or [],
            },
            sort_keys=False,
        )
    )
    return path


class ScenarioRun:
    """One scenario: a playground process, an optional ``easynav run`` process, and in this
    process a :class:`ScenarioMonitor`, a ``GoalManagerClient`` and the test's own publishers
    (hold, safety status), all on the test process's ROS domain (set per xdist worker by the
    repository's conftest, inherited by the children).

    Use as a context manager: ``__enter__`` writes the derived params file (the world's map and
    start pose, ``use_sim_time``), starts the processes and waits for the robot and (with
    EasyNav) the goal manager; ``__exit__`` stops EasyNav first (SIGINT: a controlled stop),
    then the playground, then the local ROS context, and loads :attr:`truth` (the playground's
    record: true trajectory, clearances, collisions).

    ``easynav="process"`` runs ``easynav run``; ``easynav=None`` leaves EasyNav to the test (an
    in-process ``EasyNavRuntime`` made from :attr:`params_path`). ``playground_parameters``
    (default :data:`PLAYGROUND_PARAMETERS`) are node parameters of the playground.

    Thread contract: main thread only; the monitor's callbacks run while the test waits
    (:meth:`spin_until`, :meth:`spin_for`).
    """

    def __init__(
        self,
        run_dir: Path,
        world: Path | str,
        params: dict,
        speed_up: float = 2.0,
        seed: int = 0,
        easynav: str | None = "process",
        ready_timeout: float = 60.0,
        playground_parameters: dict[str, Any] | None = None,
    ) -> None:
        if easynav not in ("process", None):
            raise ValueError(f"easynav must be 'process' or None, got {easynav!r}")
        self.run_dir = Path(run_dir)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.world = str(world)
        self.description = WorldDescription.resolve(self.world)
        self.speed_up = float(speed_up)
        self.ready_timeout = float(ready_timeout)
        source = self.run_dir / "scenario.params.yaml"
        source.write_text(yaml.safe_dump(params, sort_keys=False))
        self.params_path = self.run_dir / "params.yaml"
        map_file = self.run_dir / "world.map"
        self.description.world.save_map_file(map_file)
        robot = self.description.robot
        _notes, self.path_topic = derive_params(
            source, map_file, self.description.start_pose, self.params_path,
            map_yaml=self.description.map_server_yaml(self.run_dir),
            robot_radius=robot.radius if robot.declared else None, robot_height=robot.height,
            elevation_file=self.description.elevation_map(self.run_dir),
        )
        self.record_path = self.run_dir / "ground_truth.json"
        env = dict(os.environ)
        self.domain_id = int(env.get("ROS_DOMAIN_ID", "0"))
        self.children = [
            ChildProcess(
                "playground",
                [
                    sys.executable,
                    "-m",
                    "easynav.playground",
                    "--world",
                    self.world,
                    "--speed-up",
                    str(speed_up),
                    "--seed",
                    str(seed),
                    "--record",
                    str(self.record_path),
                    "--ros-args",
                    *_parameter_args(
                        PLAYGROUND_PARAMETERS
                        if playground_parameters is None
                        else playground_parameters
                    ),
                ],
                env,
                self.run_dir / "playground.log",
            )
        ]
        if easynav == "process":
            self.children.append(
                ChildProcess(
                    "easynav",
                    [_easynav_command(), "run", str(self.params_path)],
                    env,
                    self.run_dir / "easynav.log",
                )
            )
        self.easynav_exit_code: int | None = None
        self.truth: GroundTruthRecorder | None = None
        self.record: dict = {}
        self.context = None
        self.executor = None
        self.monitor = None
        self.client = None
        self._hold_pub = None
        self._teleport_pub = None
        self._safety_stop = threading.Event()
        self._safety_thread: threading.Thread | None = None
        self._safety_node = None
        self._safety_executor = None
        self._safety_lock = threading.Lock()
        self.safety_protective_stop = False
        self.safety_changes: list[tuple[float, bool, float]] = []
        self.checks: list[Callable[[], None]] = []

    # ------------------------------------------------------------------ set-up, tear-down
    def __enter__(self) -> ScenarioRun:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from scenario_monitor import ScenarioMonitor

        from easynav.system.goals.goal_manager_client import GoalManagerClient

        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=self.domain_id)
        self.executor = SingleThreadedExecutor(context=self.context)
        try:
            for child in self.children:
                child.start()
            self.monitor = ScenarioMonitor(self.path_topic, context=self.context)
            self.executor.add_node(self.monitor)
            self.client = GoalManagerClient(self.monitor)
            self._make_hold_publisher()
            self.spin_until(lambda: self.monitor.truth is not None, self.ready_timeout, "robot")
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def wait_for_goal_manager(self) -> None:
        """Wait until EasyNav's goal manager answers (process or in-process)."""
        self.spin_until(self.client.manager_available, self.ready_timeout, "goal manager")

    def __exit__(self, *exc) -> None:
        import rclpy

        self._stop_safety_channel()
        for child in reversed(self.children):  # EasyNav first: it stops the robot
            code = child.stop()
            if child.name == "easynav":
                self.easynav_exit_code = code
        if self.monitor is not None:
            self._write_observations()
        if self.executor is not None:
            self.executor.shutdown()
        if self.monitor is not None:
            self.monitor.destroy_node()
        if self.context is not None and self.context.ok():
            rclpy.shutdown(context=self.context)
        try:
            self.record = json.loads(self.record_path.read_text())
            self.truth = GroundTruthRecorder.load(self.record_path)
            if self.monitor is not None:
                # EasyNav's estimates beside the truth (localisation error), kept as run.json.
                self.truth.estimated_poses = list(self.monitor.estimates.estimated_poses)
                self.truth.save(self.run_dir / "run.json")
        except (OSError, ValueError) as err:
            if exc[0] is None:
                raise ScenarioError(f"no ground truth from the playground: {err}") from err

    def _write_observations(self) -> None:
        """Keep what the monitor saw beside the logs (``observed.txt``), for post-mortems."""
        with self.monitor.lock:
            lines = [
                f"{d.stamp:8.2f} D {d.name} [{d.level}] {d.message}"
                for d in self.monitor.diagnostics
            ]
            lines += [f"{r.stamp:8.2f} R {r.message}" for r in self.monitor.reports]
            lines += [f"{t:8.2f} C {vx:.3f} {wz:.3f}" for t, vx, wz in self.monitor.commands]
        lines.sort(key=lambda line: float(line.split()[0]))
        (self.run_dir / "observed.txt").write_text("\n".join(lines) + "\n")

    # ------------------------------------------------------------------ waiting
    def check_children(self) -> None:
        """Raise :class:`ScenarioError` with the log tail when a process died."""
        for child in self.children:
            if child.exit_code() is not None:
                raise ScenarioError(
                    f"{child.name} exited with code {child.exit_code()}:\n{_tail(child, 40)}"
                )
        for check in self.checks:
            check()

    def spin_until(self, predicate: Callable[[], Any], timeout: float, what: str) -> Any:
        """Spin until ``predicate()`` is truthy (returns it); ScenarioError after ``timeout``
        wall seconds or when a process died.
        """
        deadline = time.monotonic() + timeout
        while True:
            value = predicate()
            if value:
                return value
            self.check_children()
            if time.monotonic() > deadline:
                raise ScenarioError(
                    f"timed out after {timeout:.0f} s waiting for {what}\n"
                    + "\n".join(f"--- {c.name}:\n{_tail(c, 25)}" for c in self.children)
                )
            self.executor.spin_once(timeout_sec=SPIN_STEP)

    def spin_for_sim(self, seconds: float, timeout: float | None = None) -> None:
        """Spin for ``seconds`` of simulated time."""
        end = self.sim_time() + seconds
        limit = timeout if timeout is not None else 3.0 * seconds / self.speed_up + 10.0
        self.spin_until(lambda: self.sim_time() >= end, limit, f"{seconds} s of simulated time")

    # ------------------------------------------------------------------ the robot
    def sim_time(self) -> float:
        """Simulated time now (s): the monitor's clock (``/clock``, depth 1: the latest)."""
        return self.monitor.sim_now()

    def position(self) -> tuple[float, float]:
        """True position of the robot (the latest ``ground_truth`` read)."""
        _, x, y, _ = self.monitor.truth
        return x, y

    def hold_robot(self, held: bool) -> None:
        """Hold the robot in place (wheels blocked) or release it: latched ``playground/hold``.

        Waits until the playground's subscription matched the publisher (DDS discovery of a new
        publisher takes a moment), so the hold applies at once.
        """
        from std_msgs.msg import Bool

        self.spin_until(
            lambda: self._hold_pub.get_subscription_count() > 0, 20.0, "playground/hold"
        )
        self._hold_pub.publish(Bool(data=bool(held)))

    def _make_hold_publisher(self) -> None:
        # Made at start-up: discovery runs while the scenario gets going.
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from std_msgs.msg import Bool

        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        self._hold_pub = self.monitor.create_publisher(Bool, "playground/hold", latched)
        from geometry_msgs.msg import Pose2D

        self._teleport_pub = self.monitor.create_publisher(Pose2D, "playground/teleport", 10)

    def teleport_robot(self, x: float, y: float, yaw: float) -> None:
        """Carry the robot to ``(x, y, yaw)`` (map frame) without odometry: a kidnap
        (``playground/teleport``). Waits until the playground's subscription matched."""
        from geometry_msgs.msg import Pose2D

        self.spin_until(
            lambda: self._teleport_pub.get_subscription_count() > 0, 20.0, "playground/teleport"
        )
        self._teleport_pub.publish(Pose2D(x=float(x), y=float(y), theta=float(yaw)))

    # ------------------------------------------------------------------ the safety channel
    def start_safety_channel(self, period: float = 0.05) -> None:
        """Publish the safety channel's status on ``easynav_safety_status`` every ``period``
        wall seconds, with ``protective_stop`` = :attr:`safety_protective_stop`, from a node
        and executor of its own in a thread of its own: the certified channel it stands in for
        does not wait until the test has read its messages (on a loaded machine the test's
        executor runs seconds behind), and its clock (``/clock``, served by its own executor)
        stays current.

        Each publication that changes ``protective_stop`` is kept in :attr:`safety_changes`
        as ``(stamp, protective_stop, wall)``: this process's simulated clock and the wall clock
        (``time.time()``) when it was sent, the moment EasyNav could first know. (The simulated
        clock of a busy process lags the playground's; the wall clock is the machine's.)
        """
        from easynav_interfaces.msg import SafetyStatus
        from rclpy.clock import Clock, ClockType
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.parameter import Parameter
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        node = Node(
            "scenario_safety_channel",
            context=self.context,
            parameter_overrides=[Parameter("use_sim_time", value=True)],
        )
        publisher = node.create_publisher(
            SafetyStatus,
            "easynav_safety_status",
            QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE),
        )
        msg = SafetyStatus()
        sent: list[bool] = []

        def publish() -> None:
            stop = bool(self.safety_protective_stop)
            stamp = node.get_clock().now()
            wall = time.time()
            msg.header.stamp = stamp.to_msg()
            msg.protective_stop = stop
            msg.speed_limited = False
            msg.active_field = "protective" if stop else "free"
            publisher.publish(msg)
            if not sent or sent[-1] != stop:
                sent.append(stop)
                with self._safety_lock:
                    self.safety_changes.append((stamp.nanoseconds * 1e-9, stop, wall))

        node.create_timer(period, publish, clock=Clock(clock_type=ClockType.STEADY_TIME))
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(node)
        self._safety_node, self._safety_executor = node, executor
        self._safety_thread = threading.Thread(
            target=self._spin_safety_channel, name="safety-channel", daemon=True
        )
        self._safety_thread.start()

    def _spin_safety_channel(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            while not self._safety_stop.is_set():
                self._safety_executor.spin_once(timeout_sec=0.05)
        except ExternalShutdownException:
            pass

    def set_protective_stop(self, stop: bool) -> tuple[float, float]:
        """Signal (or release) a protective stop; returns ``(stamp, wall)`` of the first status
        sent with it (see :meth:`start_safety_channel`; waits for it).
        """
        self.safety_protective_stop = bool(stop)
        found: list[tuple[float, float]] = []

        def sent() -> bool:
            with self._safety_lock:
                changes = list(self.safety_changes)
            if changes and changes[-1][1] == bool(stop):
                found.append((changes[-1][0], changes[-1][2]))
                return True
            return False

        self.spin_until(sent, 10.0, f"the safety channel to send protective_stop={stop}")
        return found[0]

    def _stop_safety_channel(self) -> None:
        if self._safety_thread is not None:
            self._safety_stop.set()
            self._safety_thread.join(5.0)
            self._safety_executor.shutdown()
            self._safety_node.destroy_node()
            self._safety_thread = None

    # ------------------------------------------------------------------ goals
    def send_goals(self, goals: list[tuple[float, float, float]]) -> float:
        """Send ``[(x, y, yaw)]`` in the map frame; wait until accepted. Returns the sim time."""
        from easynav.core.types import Header, Pose, PoseStamped
        from easynav.system.goals.goal_client_state import GoalClientState as S

        stamp = self.monitor.sim_now()
        self.client.send_goals(
            [PoseStamped(Header(stamp, "map"), Pose.from_xy_yaw(x, y, yaw)) for x, y, yaw in goals]
        )
        self.spin_until(lambda: self.client.get_state() is not S.SENT_GOAL, 30.0, "goal answer")
        state = self.client.get_state()
        if state is not S.ACCEPTED_AND_NAVIGATING:
            result = self.client.get_result()
            raise ScenarioError(
                f"goals not accepted: {state.name} "
                f"({result.status_message if result is not None else ''})"
            )
        return self.sim_time()

    def wait_for_end(self, timeout: float) -> tuple[str, str]:
        """Wait for a terminal client state; returns ``(state name, status_message)``."""
        self.spin_until(lambda: self.client.get_state().is_terminal, timeout, "mission end")
        result = self.client.get_result()
        return self.client.get_state().name, (result.status_message if result else "")

    # ------------------------------------------------------------------ figures
    def commands_applied(self, start: float, end: float) -> list[tuple[float, float, float]]:
        """``(stamp, v, w)`` of every command the robot took between two stamps, from the
        playground's record (after the run): what reached the robot, in simulated time.
        """
        return [(t, v, w) for t, v, w, _ in self.record.get("commands", []) if start <= t <= end]

    def first_zero_received_after(self, wall: float) -> tuple[float, float] | None:
        """``(stamp, received)`` of the first zero command the robot received at or after the
        wall-clock time ``wall`` (the playground's record, after the run), or None.
        """
        for t, v, w, received in self.record.get("commands", []):
            if received is not None and received >= wall and v == 0.0 and w == 0.0:
                return t, received
        return None

    def sim_time_at_wall(self, wall: float) -> float | None:
        """The playground's simulated time when the wall clock read ``wall``, interpolated
        between the commands it received just before and after (the record pairs each with the
        step that applied it; EasyNav republishes at least every 0.1 s), or None outside them.

        Not ``wall × speed_up``: on a loaded machine the playground runs slower than its
        nominal speed-up, and a wall-clock interval converted at the nominal rate spans more
        simulated time than went by.
        """
        events = [(received, t) for t, _, _, received in self.record.get("commands", [])
                  if received is not None]
        before = [e for e in events if e[0] <= wall]
        after = [e for e in events if e[0] > wall]
        if not before or not after:
            return None
        (r0, t0), (r1, t1) = before[-1], after[0]
        return t0 + (t1 - t0) * (wall - r0) / (r1 - r0)

    def pose_at(self, stamp: float) -> tuple[float, float]:
        """True position at the last recorded pose not after ``stamp`` (after the run)."""
        before = [(x, y) for t, x, y, _ in self.truth.true_poses if t <= stamp]
        if not before:
            raise ScenarioError(f"no true pose recorded at or before t={stamp:.2f} s")
        return before[-1]

    def true_poses_between(self, start: float, end: float) -> list[tuple[float, float, float]]:
        """``(stamp, x, y)`` of the true trajectory (after the run)."""
        return [(t, x, y) for t, x, y, _ in self.truth.true_poses if start <= t <= end]

    def min_clearance_between(self, start: float, end: float) -> float:
        """Smallest robot-edge gap to walls and obstacles between two stamps (after the run)."""
        values = [c for t, c in self.truth.clearances if start <= t <= end]
        return min(values, default=math.nan)


def _easynav_command() -> str:
    """The ``easynav`` command of this environment (beside the interpreter, else on PATH)."""
    beside = Path(sys.executable).parent / "easynav"
    found = str(beside) if beside.exists() else shutil.which("easynav")
    if not found:
        raise ScenarioError("the 'easynav' command is neither beside Python nor on PATH")
    return found


def _parameter_args(values: dict[str, Any]) -> list[str]:
    """``-p name:=value`` arguments for a node's command line."""
    args = []
    for name, value in values.items():
        text = str(value).lower() if isinstance(value, bool) else repr(value)
        args += ["-p", f"{name}:={text}"]
    return args


def _tail(child: ChildProcess, lines: int) -> str:
    """The last ``lines`` lines of a process's log, without the sensors node's routine notes
    on dropped out-of-range beams (they would fill the tail).
    """
    try:
        text = child.log_path.read_text(errors="replace")
    except FileNotFoundError:
        return ""
    kept = [line for line in text.splitlines() if "ranges (" not in line]
    return "\n".join(kept[-lines:])
