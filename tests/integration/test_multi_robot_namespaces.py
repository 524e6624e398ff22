"""Two EasyNav instances in namespaces r1 and r2 (issue #21): one by ``namespace``, one by the
original's ``--ros-args -r __ns:=/r2``, from one params file (sections ``r1/<node>`` and
``/r2/<node>``); topics, TF topics and frames apart, one saved configuration file each."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest
import yaml

from easynav.common.tf import get_tf_buffer
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros
#: ROS's own global topics, which every node has.
ROS_GLOBAL = {"/parameter_events", "/rosout", "/clock"}


def _topics_by_namespace(node) -> dict[str, set[str]]:
    """Every topic of the graph by the namespace of the nodes with an endpoint on it (by
    endpoint, not by node name: a node of a finished test may linger under the same name)."""
    result: dict[str, set[str]] = {}
    for topic, _types in node.get_topic_names_and_types():
        for info in (*node.get_publishers_info_by_topic(topic),
                     *node.get_subscriptions_info_by_topic(topic)):
            result.setdefault(info.node_namespace, set()).add(topic)
    return result


def test_two_namespaced_instances_keep_apart_and_save_their_own_configuration(
    tmp_path, runtime_factory
):
    document = {}
    for robot, rt_freq in (("r1", 20.0), ("r2", 40.0)):
        params = system_params(
            **{
                "controller_node.dummy.rt_freq": rt_freq,
                "system_node.tf_prefix": robot,
                "sensors_node.sensors": ["laser"],
                "sensors_node.laser.topic": "scan",
                "sensors_node.laser.type": "sensor_msgs/msg/LaserScan",
            }
        )
        # Both spellings of a namespaced section: the original's "r1/node" and ROS's "/r2/node".
        key = robot if robot == "r1" else f"/{robot}"
        document.update({f"{key}/{node}": section for node, section in params.items()})
    path = tmp_path / "fleet.yaml"
    path.write_text(yaml.safe_dump(document))
    log_dir = Path(os.environ["ROS_LOG_DIR"])
    r1 = runtime_factory(str(path), namespace="r1")
    r2 = runtime_factory(str(path), ros_args=["-r", "__ns:=/r2"])
    assert r1.start(), r1.error
    assert r2.start(), r2.error

    assert r2.system_node.get_fully_qualified_name() == "/r2/system_node"
    assert r2.system_node.controller_node.plugins[0].plugin.rt_freq == 40.0
    assert get_tf_buffer("r2").get_tf_info().odom_frame == "r2/odom"
    assert get_tf_buffer("r1").get_tf_info().robot_footprint_frame == "r1/base_footprint"

    # Every topic of each instance is inside its namespace: the command, the goal topics,
    # the sensors and TF; nothing of one is in the other's. (The graph fills in as discovery
    # goes: wait until it lists what each instance must have, then look at everything.)
    graph = r1.system_node
    expected = ("cmd_vel", "easynav_control", "scan", "tf", "tf_static", "goal_pose")
    wanted = {robot: {f"/{robot}/{topic}" for topic in expected} for robot in ("r1", "r2")}
    deadline = time.monotonic() + 30.0
    seen = _topics_by_namespace(graph)
    while time.monotonic() < deadline and not all(
        wanted[robot] <= seen.get(f"/{robot}", set()) for robot in wanted
    ):
        time.sleep(0.05)
        seen = _topics_by_namespace(graph)
    for robot in ("r1", "r2"):
        topics = seen.get(f"/{robot}", set())
        assert wanted[robot] <= topics, sorted(wanted[robot] - topics)
        outside = {t for t in topics if not t.startswith(f"/{robot}/")}
        assert outside <= ROS_GLOBAL, sorted(outside)
    assert seen["/r1"] & seen["/r2"] <= ROS_GLOBAL

    # Each saves its own configuration file, with its own parameters.
    saved = {}
    for robot, runtime in (("r1", r1), ("r2", r2)):
        fingerprint = runtime.system_node.safety.fingerprint
        name = f"easynav_configuration_{robot}_{fingerprint.hash}.txt"
        saved[robot] = (log_dir / name).read_text()
    assert "controller_node dummy.rt_freq (double) = 20.0" in saved["r1"].replace("/", " ")
    assert "controller_node dummy.rt_freq (double) = 40.0" in saved["r2"].replace("/", " ")
    assert saved["r1"] != saved["r2"]
