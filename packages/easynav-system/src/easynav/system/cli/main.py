"""``easynav``: run, check and inspect EasyNav; send goals; run the playground demo."""

from __future__ import annotations

import argparse
import os
import sys
from importlib import metadata

from easynav.system.cli.params_file import ParamsFileError, load_params_file, unknown_node_names


def _version() -> str:
    try:
        return metadata.version("easynav-core")
    except metadata.PackageNotFoundError:
        return "unknown"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="easynav",
        description="EasyNav for Python: a ROS 2 navigation system configured by one YAML file.",
    )
    parser.add_argument("--version", action="version", version=f"easynav {_version()}")
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run EasyNav with a params file until Ctrl-C")
    run.add_argument("params", help="ROS 2 params file (YAML)")
    run.add_argument("--namespace", default="", help="namespace of every EasyNav node")
    run.add_argument(
        "--duration", type=float, default=None, help="stop by itself after this many seconds"
    )
    run.add_argument(
        "--ros-args", dest="ros_args", nargs=argparse.REMAINDER, default=[],
        help="further ROS arguments (remappings, -p name:=value, ...)",
    )

    check = sub.add_parser("check", help="configure without starting: report what is wrong")
    check.add_argument("params")
    check.add_argument("--namespace", default="")
    check.add_argument(
        "--strict", action="store_true",
        help="a key no plugin declares is an error (default: a warning)",
    )

    plugins = sub.add_parser("plugins", help="list installed plugins by kind")
    plugins.add_argument(
        "--import", dest="do_import", action="store_true",
        help="also import every plugin and report those that fail",
    )
    plugins.add_argument(
        "--describe", metavar="NAME", default=None,
        help="a plugin's parameters (name, type, default, unit, range, description), topics "
             "and NavState keys read and written",
    )

    goal = sub.add_parser("goal", help="send a goal to a running EasyNav and follow it")
    goal.add_argument("args", nargs=argparse.REMAINDER, help="X Y [YAW] [options]")

    demo = sub.add_parser("demo", help="the playground demo: a simulated robot navigating")
    demo.add_argument("args", nargs=argparse.REMAINDER, help="demo options (see easynav demo -h)")
    return parser


def _load_params_or_exit(path: str) -> dict:
    try:
        document = load_params_file(path)
    except ParamsFileError as exc:
        print(f"easynav: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    for name in unknown_node_names(document):
        print(f"easynav: warning: '{name}' in {path} is not an EasyNav node", file=sys.stderr)
    return document


def _report_unknown_keys(path: str, document: dict, strict: bool) -> int:
    """Print each key nothing declares; the number found."""
    from easynav.system.cli.unknown_keys import unknown_keys

    found = unknown_keys(document)
    level = "error" if strict else "warning"
    for item in found:
        print(f"easynav: {level}: {path}: {item.message()}", file=sys.stderr)
    return len(found)


def cmd_run(args: argparse.Namespace) -> int:
    _load_params_or_exit(args.params)
    from easynav.common.compiled_kernels import enable_child_compilation
    from easynav.system.easynav_runtime import EasyNavRuntime

    # A long-lived process: numba kernels it has never run are compiled by a child process and
    # only loaded here, so LLVM's compile-time state (~80 MB with the costmap stack and MPPI)
    # does not stay resident for the whole run.
    enable_child_compilation()
    runtime = EasyNavRuntime(args.params, args.namespace, args.ros_args)
    if not runtime.start():
        print(f"easynav: failed to start: {runtime.error}", file=sys.stderr)
        runtime.stop()
        return 2
    plugins = runtime.system_node.loaded_plugins()
    print("EasyNav active. Plugins:")
    for node, items in plugins.items():
        for alias, name in items:
            print(f"  {node}: {alias} [{name}]")
    sys.stdout.flush()
    runtime.wait(args.duration)
    result = runtime.stop()
    if result.exit_code:
        print(f"easynav: stopped: {result.reason} (exit code {result.exit_code})", file=sys.stderr)
    else:
        print(f"EasyNav stopped: {result.reason}")
    return result.exit_code


def cmd_check(args: argparse.Namespace) -> int:
    document = _load_params_or_exit(args.params)
    if _report_unknown_keys(args.params, document, args.strict) and args.strict:
        print("easynav: configuration invalid: unknown parameters (--strict)", file=sys.stderr)
        return 2
    # Nothing here needs the network: keep DDS discovery inside this process.
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    from easynav.system.easynav_runtime import EasyNavRuntime

    runtime = EasyNavRuntime(args.params, args.namespace, install_signal_handlers=False)
    node = runtime.system_node
    node.trigger_configure()
    ok = node.lifecycle_state() == "inactive"
    message = node.error_message
    plugins = node.loaded_plugins() if ok else {}
    runtime.stop()
    if not ok:
        print(f"easynav: configuration invalid: {message}", file=sys.stderr)
        return 2
    print(f"{args.params}: configuration OK")
    for name, items in plugins.items():
        for alias, plugin in items:
            print(f"  {name}: {alias} [{plugin}]")
    return 0


def cmd_plugins(args: argparse.Namespace) -> int:
    if args.describe:
        from easynav.system.plugin_reference import describe_text, find_plugin

        try:
            plugin = find_plugin(args.describe)
        except (LookupError, ImportError) as exc:
            print(f"easynav: {exc}", file=sys.stderr)
            return 2
        print(describe_text(plugin))
        return 0
    from easynav.core.plugins.discovery import check_imports, list_plugins, other_plugin_groups
    from easynav.core.plugins.plugin_kinds import ALL_KINDS

    infos = list_plugins()
    for kind in ALL_KINDS:
        rows = [i for i in infos if i.kind is kind]
        print(f"{kind.name} ({kind.entry_point_group}):")
        if not rows:
            print("  (none installed)")
        for info in rows:
            print(f"  {info.name:<58} {info.distribution} {info.version}")
    for group, rows in other_plugin_groups().items():
        print(f"{group.removeprefix('easynav.').replace('_', ' ')} ({group}):")
        for info in rows:
            print(f"  {info.name:<58} {info.distribution} {info.version}")
    if args.do_import:
        problems = check_imports()
        for problem in problems:
            print(f"error: {problem}", file=sys.stderr)
        return 1 if problems else 0
    return 0


def cmd_goal(args: argparse.Namespace) -> int:
    from easynav.system.goals.goal_command import goal_command

    return goal_command(args.args)


def cmd_demo(args: argparse.Namespace) -> int:
    try:
        from easynav.playground.demo import main as demo_main
    except ImportError as exc:
        print(
            f"easynav: the demo needs the easynav-playground distribution ({exc}): "
            "pip install easynav-playground",
            file=sys.stderr,
        )
        return 2
    return demo_main(args.args)


COMMANDS = {
    "run": cmd_run,
    "check": cmd_check,
    "plugins": cmd_plugins,
    "goal": cmd_goal,
    "demo": cmd_demo,
}


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    # `goal` and `demo` own their options (including -h): hand them everything after the word.
    if argv and argv[0] in ("goal", "demo"):
        return COMMANDS[argv[0]](argparse.Namespace(command=argv[0], args=argv[1:]))
    args = build_parser().parse_args(argv)
    return COMMANDS[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
