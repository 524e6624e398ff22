"""The configuration fingerprint (the SHA-256 of every effective parameter, computed on each
configure) end to end: the saved file, the log line, the latched ``easynav_configuration`` topic,
NavState, and what changes the hash and what does not.
"""

from __future__ import annotations

import os
import re
import subprocess
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy
from safety_e2e_harness import RosoutListener
from safety_e2e_params import system
from std_msgs.msg import String

from easynav.system.safety import ros_log_dir

pytestmark = pytest.mark.ros

LOG_LINE = re.compile(r"Configuration SHA-256: ([0-9a-f]{64})\n  \((.+)\)\. Plugins:")


def sha256sum(path: Path) -> str:
    """The hash an integrator gets with coreutils' ``sha256sum``."""
    output = subprocess.run(["sha256sum", str(path)], capture_output=True, text=True, check=True)
    return output.stdout.split()[0]


def configuration_hash(start_easynav, document, namespace="") -> str:
    rt = start_easynav(document, namespace)
    value = rt.nav_state.get("configuration_hash")
    rt.stop()
    return value


def saved_file(configuration: str, namespace: str = "") -> Path:
    middle = f"{namespace}_" if namespace else ""
    return ros_log_dir() / f"easynav_configuration_{middle}{configuration}.txt"


def reordered(value: Any) -> Any:
    """The same document with every mapping's keys in reverse order."""
    if isinstance(value, dict):
        return {k: reordered(value[k]) for k in reversed(list(value))}
    return value


def test_saved_file_log_line_topic_and_navstate_agree_on_the_hash(ros, start_easynav):
    log = RosoutListener(ros)
    rt = start_easynav(system())
    configuration = rt.nav_state.get("configuration_hash")
    assert re.fullmatch(r"[0-9a-f]{64}", configuration)
    path = saved_file(configuration)
    assert path.parent == Path(os.environ["ROS_LOG_DIR"])  # set per test run by the conftest
    assert sha256sum(path) == configuration

    # Looked up by its hash: another EasyNav's log lines may reach /rosout too.
    assert ros.spin_until(lambda: log.find(f"Configuration SHA-256: {configuration}"), 5.0)
    (_, _, text) = log.find(f"Configuration SHA-256: {configuration}")[-1]
    logged_hash, logged_path = LOG_LINE.search(text).groups()
    assert (logged_hash, Path(logged_path)) == (configuration, path)
    assert "controller_node: ctrl [easynav_controller/FaultyController]" in text

    lines = path.read_text().splitlines()
    assert lines == sorted(lines)
    assert "controller_node/cmd_timeout (double) = 0.2" in lines
    assert 'controller_node/controller_types (string_array) = ["ctrl"]' in lines
    assert "system_node/safety.mode (bool) = false" in lines

    # A late subscriber still gets the latched configuration.
    late = ros.create_node("late_subscriber")
    received: list[str] = []
    latched = QoSProfile(
        depth=1,
        reliability=QoSReliabilityPolicy.RELIABLE,
        durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
    )
    late.create_subscription(
        String, "/easynav_configuration", lambda m: received.append(m.data), latched
    )
    assert ros.spin_until(lambda: received, timeout=5.0)
    first_line, rest = received[-1].split("\n", 1)
    assert first_line == f"# SHA-256: {configuration}"
    assert rest == path.read_text()


def test_same_configuration_same_hash_across_runs_and_parameter_orders(start_easynav):
    document = system()
    first = configuration_hash(start_easynav, document)
    path = saved_file(first)
    written = path.stat().st_mtime_ns
    assert configuration_hash(start_easynav, reordered(document)) == first
    # Seen before: not saved again.
    assert path.stat().st_mtime_ns == written


def test_changing_one_parameter_changes_the_hash_and_one_line(start_easynav):
    before = configuration_hash(start_easynav, system())
    after = configuration_hash(start_easynav, system(**{"controller_node.cmd_timeout": 0.25}))
    assert after != before
    old = set(saved_file(before).read_text().splitlines())
    new = set(saved_file(after).read_text().splitlines())
    assert old - new == {"controller_node/cmd_timeout (double) = 0.2"}
    assert new - old == {"controller_node/cmd_timeout (double) = 0.25"}


def test_changing_a_default_changes_the_hash(start_easynav, monkeypatch):
    from easynav.system import system_node

    before = configuration_hash(start_easynav, system())
    # A new version of EasyNav with another default, the params file untouched.
    monkeypatch.setattr(system_node, "SYSTEM_PARAMETERS", tuple(
        replace(p, default=25.0) if p.name == "update_frequency" else p
        for p in system_node.SYSTEM_PARAMETERS
    ))
    after = configuration_hash(start_easynav, system())
    assert after != before
    assert "system_node/update_frequency (double) = 25.0" in saved_file(after).read_text()


def test_a_string_with_a_newline_cannot_fake_another_line(start_easynav):
    fake = "earth\ncontroller_node/cmd_timeout (double) = 9.0"
    configuration = configuration_hash(start_easynav, system(**{"system_node.world_frame": fake}))
    lines = saved_file(configuration).read_text().splitlines()
    assert [line for line in lines if line.startswith("controller_node/cmd_timeout")] == [
        "controller_node/cmd_timeout (double) = 0.2"
    ]
    assert (
        'system_node/world_frame (string) = "earth\\ncontroller_node/cmd_timeout (double) '
        '= 9.0"' in lines
    )
    assert all(re.fullmatch(r"[a-z_]+_node/\S+ \([a-z_]+\) = .*", line) for line in lines)


def test_a_namespace_goes_into_the_file_name_and_the_topic(ros, start_easynav):
    namespaced = {f"/robot1/{node}": params for node, params in system().items()}
    received: list[str] = []
    node = ros.create_node("fleet_manager")
    latched = QoSProfile(
        depth=1,
        reliability=QoSReliabilityPolicy.RELIABLE,
        durability=QoSDurabilityPolicy.TRANSIENT_LOCAL,
    )
    node.create_subscription(
        String, "/robot1/easynav_configuration", lambda m: received.append(m.data), latched
    )
    rt = start_easynav(namespaced, namespace="robot1")
    configuration = rt.nav_state.get("configuration_hash")
    path = saved_file(configuration, "robot1")
    assert sha256sum(path) == configuration
    assert "controller_node/cmd_timeout (double) = 0.2" in path.read_text()  # its params file
    assert ros.spin_until(lambda: received, timeout=5.0)
    assert received[-1].startswith(f"# SHA-256: {configuration}\n")
