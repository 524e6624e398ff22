"""``easynav goal X Y [YAW]``: send one goal to a running EasyNav and follow it to the end.

``easynav goal --latlon LAT LON [YAW] --origin LAT0 LON0``: the goal given in latitude and
longitude, converted to the map frame whose geodetic origin is ``(LAT0, LON0)``.

Exit codes: 0 navigation finished; 1 it did not (rejected, failed or aborted, cancelled by
someone else, protocol error), the reason on stderr; 2 bad arguments; 3 no goal manager found;
4 ``--timeout`` expired (the goal is cancelled); 130 interrupted by Ctrl-C (the goal is
cancelled).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Sequence
from typing import Any, TextIO

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor

from easynav.core.types import Header, Pose, PoseStamped
from easynav.system.goals.goal_client_state import GoalClientState as S
from easynav.system.goals.goal_manager_client import GoalManagerClient
from easynav.system.goals.navigation_control import NavigationControl
from easynav.system.goals.safe_interrupt import SafeInterrupt

EXIT_FINISHED = 0
EXIT_NOT_FINISHED = 1
EXIT_USAGE = 2
EXIT_NO_MANAGER = 3
EXIT_TIMEOUT = 4
EXIT_INTERRUPTED = 130

PROGRESS_PERIOD = 1.0  # s between two progress lines
CANCEL_WAIT = 3.0  # s to wait for the goal manager to confirm a cancellation
SPIN_STEP = 0.05  # s per executor wait: fast enough for Ctrl-C and progress


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``easynav goal``."""
    parser = argparse.ArgumentParser(
        prog="easynav goal",
        description="Send a goal to a running EasyNav and follow it to the end.",
        epilog="Exit codes: 0 finished, 1 not finished (reason printed), 2 bad arguments, "
        "3 no goal manager, 4 timeout, 130 Ctrl-C. Arguments after --ros-args go to ROS.",
    )
    parser.add_argument("x", type=float, help="goal x (m) in --frame (latitude with --latlon)")
    parser.add_argument("y", type=float, help="goal y (m) in --frame (longitude with --latlon)")
    parser.add_argument("yaw", type=float, nargs="?", default=0.0, help="goal yaw (rad), 0")
    parser.add_argument("--frame", default="map", help="frame of the goal (default: map)")
    parser.add_argument("--namespace", default="", help="EasyNav's namespace (default: none)")
    parser.add_argument(
        "--latlon", action="store_true",
        help="X Y are latitude and longitude (degrees, WGS 84): the goal is that point in the "
        "map frame, whose geodetic origin --origin gives (UTM of the origin's zone, x east, "
        "y north; needs easynav-localizers[gps])",
    )
    parser.add_argument(
        "--origin", type=float, nargs=2, metavar=("LAT", "LON"), default=None,
        help="geodetic origin of the map frame, for --latlon (the localizer's "
        "latitude_origin/longitude_origin)",
    )
    parser.add_argument(
        "--timeout", type=float, default=None,
        help="give up (and cancel the goal) after this many seconds (default: wait forever)",
    )
    parser.add_argument(
        "--connect-timeout", type=float, default=10.0,
        help="how long to look for the goal manager (s, default 10)",
    )
    return parser


def goal_command(
    argv: Sequence[str] | None = None,
    *,
    context: Context | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Run ``easynav goal`` with ``argv`` (without the program and sub-command names); returns
    the exit code (see the module docstring).

    ``context``: an initialised rclpy context to use (and leave initialised); by default the
    command initialises and shuts down its own, with no ROS signal handlers, so that Ctrl-C
    raises ``KeyboardInterrupt`` here and the goal can still be cancelled over ROS.
    Thread contract: runs in the calling thread (its own node and SingleThreadedExecutor).
    """
    out = out or sys.stdout
    err = err or sys.stderr
    args_list = list(sys.argv[1:] if argv is None else argv)
    ros_args: list[str] = []
    if "--ros-args" in args_list:
        split = args_list.index("--ros-args")
        args_list, ros_args = args_list[:split], args_list[split:]
    parser = build_parser()
    try:
        args = parser.parse_args(args_list)
    except SystemExit as exc:  # --help (0) or a usage error (2): argparse printed why
        return int(exc.code or 0)
    problem = _check_arguments(args)
    if problem:
        print(f"easynav goal: error: {problem}", file=err)
        return EXIT_USAGE
    if args.latlon:
        try:
            lat, lon = args.x, args.y
            args.x, args.y = latlon_to_map(lat, lon, args.origin)
        except ImportError as exc:
            print(f"easynav goal: error: {exc}", file=err)
            return EXIT_USAGE
        print(f"Goal ({lat:.8f}, {lon:.8f}) is ({args.x:.3f}, {args.y:.3f}) in 'map'", file=out)

    own_context = context is None
    if own_context:
        context = Context()
        rclpy.init(args=["easynav_goal", *ros_args], context=context)
    node = None
    executor = None
    client = None
    try:
        node = rclpy.create_node(
            f"easynav_goal_{os.getpid()}", namespace=args.namespace, context=context
        )
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        client = GoalManagerClient(node)
        with SafeInterrupt() as interrupt:
            return _run(args, node, executor, client, interrupt, out, err)
    finally:
        if client is not None:
            client.destroy()
        if executor is not None:
            executor.shutdown()
        if node is not None:
            node.destroy_node()
        if own_context:
            rclpy.shutdown(context=context)


def _check_arguments(args: argparse.Namespace) -> str | None:
    for name in ("x", "y", "yaw"):
        if not math.isfinite(getattr(args, name)):
            return f"{name} must be a finite number, got {getattr(args, name)}"
    if args.timeout is not None and not (math.isfinite(args.timeout) and args.timeout > 0):
        return f"--timeout must be a positive number of seconds, got {args.timeout}"
    if not (math.isfinite(args.connect_timeout) and args.connect_timeout > 0):
        return f"--connect-timeout must be a positive number of seconds, got {args.connect_timeout}"
    if not args.frame:
        return "--frame must not be empty"
    if args.latlon:
        if args.origin is None:
            return "--latlon needs --origin LAT LON (the map frame's geodetic origin)"
        for name, value, limit in (("latitude", args.x, 90.0), ("longitude", args.y, 180.0),
                                   ("--origin latitude", args.origin[0], 90.0),
                                   ("--origin longitude", args.origin[1], 180.0)):
            if not (math.isfinite(value) and abs(value) <= limit):
                return f"{name} must be within ±{limit:g} degrees, got {value}"
        if args.frame != "map":
            return "--latlon goals are in the map frame (leave --frame out)"
    elif args.origin is not None:
        return "--origin is only for --latlon"
    return None


def latlon_to_map(
    latitude: float, longitude: float, origin: Sequence[float]
) -> tuple[float, float]:
    """Map-frame ``(x, y)`` of a geodetic point, the map origin at ``origin`` ``(lat, lon)``:
    UTM (pyproj, the origin's zone) minus the origin's UTM, as the GNSS localizers compute.

    Raises ImportError naming the package when the geodesy is not installed.
    """
    try:
        from easynav.localizers.fusion.utm_projection import UtmProjection
    except ImportError as exc:
        raise ImportError("easynav goal --latlon needs pyproj: "
                          "pip install easynav-localizers[gps]") from exc
    return UtmProjection(float(origin[0]), float(origin[1])).forward(latitude, longitude)


def _run(args, node, executor, client: GoalManagerClient, interrupt: SafeInterrupt,
         out: TextIO, err: TextIO) -> int:
    namespace = node.get_namespace()
    try:
        if not _spin_until(executor, client.manager_available, args.connect_timeout, interrupt):
            print(
                f"easynav goal: no EasyNav goal manager found in namespace '{namespace}' within "
                f"{args.connect_timeout:g} s (is `easynav run` up, with the same namespace and "
                "ROS_DOMAIN_ID?)",
                file=err,
            )
            return EXIT_NO_MANAGER
        stamp = node.get_clock().now().nanoseconds * 1e-9
        client.send_goal(
            PoseStamped(header=Header(stamp, args.frame),
                        pose=Pose.from_xy_yaw(args.x, args.y, args.yaw))
        )
        _say(out, f"Goal ({args.x:g}, {args.y:g}, yaw {args.yaw:g}) in '{args.frame}' sent to "
                  f"the goal manager in '{namespace}'")
        return _follow(args, executor, client, interrupt, out, err)
    except KeyboardInterrupt:
        _say(out, "Interrupted: cancelling the goal")
        _cancel_and_wait(executor, client, interrupt, out)
        return EXIT_INTERRUPTED


def _follow(args, executor, client: GoalManagerClient, interrupt: SafeInterrupt,
            out: TextIO, err: TextIO) -> int:
    deadline = None if args.timeout is None else time.monotonic() + args.timeout
    state = client.get_state()
    next_progress = time.monotonic() + PROGRESS_PERIOD
    while not state.is_terminal:
        interrupt.check()
        executor.spin_once(timeout_sec=SPIN_STEP)
        now = time.monotonic()
        new_state = client.get_state()
        if new_state is not state:
            state = new_state
            _say(out, f"State: {state.name}")
        if now >= next_progress and not state.is_terminal:
            next_progress = now + PROGRESS_PERIOD
            feedback = client.get_feedback()
            if feedback is not None:
                _say(out, _progress_line(feedback, state))
        if deadline is not None and now >= deadline and not state.is_terminal:
            _say(out, f"Timeout after {args.timeout:g} s: cancelling the goal")
            _cancel_and_wait(executor, client, interrupt, out)
            return EXIT_TIMEOUT
    result = client.get_result()
    if state is S.NAVIGATION_FINISHED:
        _say(out, f"Navigation finished in {result.navigation_time:.1f} s "
                  f"({result.distance_covered:.2f} m covered)")
        return EXIT_FINISHED
    reason = result.status_message if result is not None else "no reason given"
    print(f"easynav goal: navigation {state.name}: {reason}", file=err, flush=True)
    return EXIT_NOT_FINISHED


def _progress_line(feedback: NavigationControl, state: S) -> str:
    eta = feedback.estimated_time_remaining
    eta_text = f"{eta:.1f} s" if eta > 0.0 else "unknown"
    paused = "  (paused)" if feedback.status_message.startswith("Paused") else ""
    return (
        f"[{feedback.navigation_time:7.1f} s] distance to goal {feedback.distance_to_goal:7.2f} m"
        f"  covered {feedback.distance_covered:7.2f} m  time remaining {eta_text}"
        f"  {state.name}{paused}"
    )


def _cancel_and_wait(executor, client: GoalManagerClient, interrupt: SafeInterrupt,
                     out: TextIO) -> None:
    """Cancel the goal and wait for the answer; one more Ctrl-C stops waiting."""
    if not client.get_state().is_navigating:
        return
    client.cancel()
    try:
        confirmed = _spin_until(executor, lambda: client.get_state().is_terminal, CANCEL_WAIT,
                                interrupt, interrupt.presses)
    except KeyboardInterrupt:
        confirmed = False
    if confirmed:
        _say(out, f"Goal cancelled ({client.get_state().name})")
    else:
        _say(out, "The goal manager did not confirm the cancellation")


def _spin_until(executor: Any, done, timeout: float, interrupt: SafeInterrupt,
                presses_seen: int = 0) -> bool:
    deadline = time.monotonic() + timeout
    while True:
        if done():
            return True
        if time.monotonic() >= deadline:
            return False
        interrupt.check(presses_seen)
        executor.spin_once(timeout_sec=SPIN_STEP)


def _say(out: TextIO, text: str) -> None:
    print(text, file=out, flush=True)
