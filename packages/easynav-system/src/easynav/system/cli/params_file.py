"""Reading a ROS 2 params file before ROS does, to give errors that name the culprit."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

KNOWN_NODES = (
    "system_node",
    "controller_node",
    "localizer_node",
    "maps_manager_node",
    "planner_node",
    "recovery_node",
    "sensors_node",
)


# ROS 2 reads params files with libyaml (rcl_yaml_param_parser), which accepts a tab as an in-line
# separator (``dt:<TAB>0.1``, as the original's NavMap workshop files have); PyYAML's pure-Python
# scanner rejects it. The libyaml loader reads files as ROS does (and faster).
_ROS_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def load_ros_yaml(text: str) -> Any:
    """Parse YAML text as ROS 2 reads params files (libyaml: tabs accepted as separators)."""
    return yaml.load(text, Loader=_ROS_LOADER)  # noqa: S506 (a safe loader)


class ParamsFileError(ValueError):
    """The params file is missing, unreadable or malformed; the message names file and place."""


def load_params_file(path: str) -> dict[str, Any]:
    """Parse and check the shape of a ROS 2 params file; returns the YAML document.

    Raises :class:`ParamsFileError` for a missing file, invalid YAML (with line and column) or a
    node entry without ``ros__parameters``.
    """
    file = Path(path)
    if not file.is_file():
        raise ParamsFileError(f"params file not found: {path}")
    try:
        document = load_ros_yaml(file.read_text())
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "?"
        raise ParamsFileError(f"{path}: invalid YAML at {where}: {exc.problem}") from None
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ParamsFileError(f"{path}: cannot be read: {exc}") from None
    if not isinstance(document, dict):
        raise ParamsFileError(f"{path}: expected a mapping of node names to ros__parameters")
    for key, value in _node_entries(document):
        if not isinstance(value, dict) or "ros__parameters" not in value:
            raise ParamsFileError(f"{path}: '{key}' has no 'ros__parameters' mapping")
    return document


def _node_entries(document: dict[str, Any], prefix: str = ""):
    """Yield ``(qualified key, value)`` for each node entry (namespaces may nest)."""
    for key, value in document.items():
        name = f"{prefix}/{key}" if prefix else str(key)
        if isinstance(value, dict) and "ros__parameters" not in value and any(
            isinstance(v, dict) for v in value.values()
        ):
            yield from _node_entries(value, name)
        else:
            yield name, value


def unknown_node_names(document: dict[str, Any]) -> list[str]:
    """Entries whose node name is not an EasyNav node (likely typos), for a warning."""
    unknown = []
    for key, _ in _node_entries(document):
        node = key.rsplit("/", 1)[-1]
        if node not in KNOWN_NODES and node not in ("**", "*"):
            unknown.append(key)
    return unknown
