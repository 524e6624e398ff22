"""``easynav-playground`` / ``python -m easynav.playground``: run the simulated robot."""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import time

from easynav.playground.ros.playground_node import DEFAULT_PARAMETERS, parameter_overrides


def build_parser() -> argparse.ArgumentParser:
    """The command-line options (each sets the node parameter of the same meaning)."""
    parser = argparse.ArgumentParser(
        prog="easynav-playground",
        description="A 2D differential-drive robot simulator for EasyNav: laser scan, noisy "
        "wheel odometry, TF, /clock (simulated time), collisions and ground truth.",
        epilog="Any node parameter can also be set with --ros-args -p name:=value "
        f"({', '.join(sorted(DEFAULT_PARAMETERS))}).",
    )
    parser.add_argument(
        "--world",
        help="shipped world name (home, office), a world YAML, "
        "a map-server YAML or a .map file (default: home)",
    )
    parser.add_argument(
        "--speed-up", type=float, help="simulated seconds per wall second (default 1.0)"
    )
    parser.add_argument("--seed", type=int, help="random seed of sensor noise (default 0)")
    parser.add_argument(
        "--robots",
        type=int,
        help="number of robots (default 1); more than one: the world's first N 'robots', "
        "each with its topics under its name (r1/scan...) and its frames prefixed (r1/odom...)",
    )
    parser.add_argument(
        "--start",
        type=float,
        nargs=3,
        metavar=("X", "Y", "YAW"),
        help="robot start pose in the map frame (default: the world's)",
    )
    parser.add_argument(
        "--step", type=float, help="simulation step in simulated seconds (default 0.005)"
    )
    parser.add_argument(
        "--no-obstacles", action="store_true", help="leave the world's moving obstacles out"
    )
    parser.add_argument(
        "--hold",
        action="store_true",
        help="start with the robot held in place (wheels blocked; release it with a latched "
        "std_msgs/Bool false on playground/hold)",
    )
    parser.add_argument(
        "--record", help="write the ground truth of the run to this JSON file on exit"
    )
    parser.add_argument(
        "--duration",
        type=float,
        help="stop after this many simulated seconds (default: run until SIGINT/SIGTERM)",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the playground node until SIGINT/SIGTERM (or ``--duration``); returns the exit code.

    Shutdown order: stop the simulation thread, write the record, ``executor.shutdown()``,
    destroy the node, ``rclpy.shutdown()`` (the other order aborts the interpreter).
    """
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from easynav.playground.ros.playground_node import PlaygroundNode
    from easynav.system.executor import make_executor

    argv = list(sys.argv[1:] if argv is None else argv)
    ros_args: list[str] = []
    if "--ros-args" in argv:
        i = argv.index("--ros-args")
        argv, ros_args = argv[:i], argv[i:]
    options = build_parser().parse_args(argv)
    values: dict[str, object] = {}
    for option, name in (
        ("world", "world"),
        ("speed_up", "speed_up"),
        ("seed", "seed"),
        ("robots", "robots"),
        ("start", "start_pose"),
        ("step", "step"),
        ("record", "record"),
    ):
        if getattr(options, option) is not None:
            values[name] = getattr(options, option)
    if options.no_obstacles:
        values["moving_obstacles"] = False
    if options.hold:
        values["hold"] = True

    stop = threading.Event()
    rclpy.init(
        args=["easynav-playground", *ros_args], signal_handler_options=SignalHandlerOptions.NO
    )
    # The handler runs in the main thread and takes the event's lock: safe only because this
    # thread never holds it (it polls is_set, never waits on the event).
    previous = {
        sig: signal.signal(sig, lambda *_: stop.set()) for sig in (signal.SIGINT, signal.SIGTERM)
    }
    executor = make_executor()
    node = None
    code = 0
    try:
        node = PlaygroundNode(parameter_overrides=parameter_overrides(values))
        executor.add_node(node)
        node.start()
        last_report = time.monotonic()
        while not stop.is_set() and node.loop_running:
            executor.spin_once(timeout_sec=0.05)
            if options.duration is not None and node.sim.time >= options.duration:
                break
            if time.monotonic() - last_report > 30.0:
                last_report = time.monotonic()
                node.get_logger().info(
                    f"t={node.sim.time:.1f} s simulated, x{node.real_time_factor:.2f} real time "
                    f"({node.schedule_restarts} schedule restart(s)), "
                    f"{node.collision_count} collision(s)"
                )
    except (ValueError, FileNotFoundError, KeyError) as err:
        print(f"easynav-playground: {err}", file=sys.stderr)
        code = 2
    finally:
        if node is not None:
            try:
                node.stop()
            except Exception as err:  # the simulation thread failed: report it, exit non-zero
                print(f"easynav-playground: simulation failed: {err!r}", file=sys.stderr)
                code = 1
        executor.shutdown()
        if node is not None:
            node.destroy_node()
        rclpy.shutdown()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return code


if __name__ == "__main__":
    sys.exit(main())
