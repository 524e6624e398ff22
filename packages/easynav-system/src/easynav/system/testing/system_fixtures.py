"""pytest fixtures and helpers for system-level tests (an EasyNav runtime in the test process)."""

from __future__ import annotations

import copy
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

DUMMY_SYSTEM: dict[str, Any] = {
    "controller_node": {
        "controller_types": ["dummy"],
        "dummy": {"rt_freq": 30.0, "plugin": "easynav_controller/DummyController"},
    },
    "localizer_node": {
        "localizer_types": ["dummy"],
        "dummy": {"rt_freq": 50.0, "freq": 5.0, "plugin": "easynav_localizer/DummyLocalizer"},
    },
    "maps_manager_node": {
        "map_types": ["dummy"],
        "dummy": {"freq": 10.0, "plugin": "easynav_maps_manager/DummyMapsManager"},
    },
    "planner_node": {
        "planner_types": ["dummy"],
        "dummy": {"freq": 1.0, "plugin": "easynav_planner/DummyPlanner"},
    },
    "sensors_node": {"forget_time": 0.5},
    "recovery_node": {"recovery_manager": {"plugin": "easynav_recovery/DummyRecoveryManager"}},
    "system_node": {"position_tolerance": 0.1, "angle_tolerance": 0.05},
}


def system_params(base: dict[str, Any] | None = None, **overrides: Any) -> dict[str, Any]:
    """A params document (``{node: {"ros__parameters": {...}}}``) on wall-clock time.

    ``base`` is ``{node: params}`` (the original EasyNav's Dummy Navigation System example,
    without busy-waits, by default); ``overrides`` maps dotted paths ``"node.a.b"`` to values
    (``None`` removes).
    """
    nodes = copy.deepcopy(base if base is not None else DUMMY_SYSTEM)
    for path, value in overrides.items():
        node, *keys = path.split(".")
        target = nodes.setdefault(node, {})
        for key in keys[:-1]:
            target = target.setdefault(key, {})
        if value is None:
            target.pop(keys[-1], None)
        else:
            target[keys[-1]] = value
    document = {}
    for node, params in nodes.items():
        params.setdefault("use_sim_time", False)
        document[node] = {"ros__parameters": params}
    return document


def wait_for(predicate: Callable[[], Any], timeout: float = 5.0, period: float = 0.01) -> Any:
    """Poll ``predicate`` until it is truthy or ``timeout`` passes; returns its last value."""
    end = time.monotonic() + timeout
    value = predicate()
    while not value and time.monotonic() < end:
        time.sleep(period)
        value = predicate()
    return value


class _ParamsDumper(yaml.SafeDumper):
    """Quotes every string: ROS reads a plain ``nan``, ``on`` or ``1e3`` as a number or bool."""


_ParamsDumper.add_representer(
    str, lambda dumper, value: dumper.represent_scalar("tag:yaml.org,2002:str", value, style='"')
)


def write_params(path: Path, document: dict[str, Any]) -> str:
    """Write a params document as YAML that ROS reads back with the same types; its path."""
    Path(path).write_text(yaml.dump(document, Dumper=_ParamsDumper, sort_keys=False))
    return str(path)


@pytest.fixture
def params_file(tmp_path: Path) -> Callable[[dict[str, Any]], str]:
    """``params_file(document) -> path`` of a temporary YAML file."""
    counter = iter(range(10_000))

    def write(document: dict[str, Any]) -> str:
        return write_params(tmp_path / f"params_{next(counter)}.yaml", document)

    return write


@pytest.fixture
def runtime_factory() -> Iterator[Callable[..., Any]]:
    """``runtime_factory(params_path, namespace="", ros_args=None) -> EasyNavRuntime``;
    every runtime made is stopped at the end of the test.
    """
    from easynav.system.easynav_runtime import EasyNavRuntime

    runtimes = []

    def make(path: str, namespace: str = "", ros_args: list[str] | None = None):
        runtime = EasyNavRuntime(path, namespace, ros_args, install_signal_handlers=False)
        runtimes.append(runtime)
        return runtime

    yield make
    for runtime in runtimes:
        runtime.stop()
