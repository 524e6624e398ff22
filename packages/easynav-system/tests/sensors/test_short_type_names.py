"""Short sensor type names of the original's older params files (``type: PointCloud``)."""

from __future__ import annotations

import logging

import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters
from easynav.system.sensors import SensorsManager
from easynav.system.sensors.errors import SensorsConfigurationError
from easynav.system.sensors.handler_registry import SHORT_TYPE_NAMES, resolve_handler


@pytest.mark.parametrize("short", sorted(SHORT_TYPE_NAMES))
def test_every_short_name_resolves_to_the_handler_of_its_full_type(short):
    warnings = []
    by_alias = resolve_handler("s", short, "", "sensors_node", warn=warnings.append)
    by_full = resolve_handler("s", SHORT_TYPE_NAMES[short], "", "sensors_node")
    assert by_alias is by_full
    assert warnings == [
        f"sensors_node.s.type = '{short}' is deprecated: write the message type "
        f"'{SHORT_TYPE_NAMES[short]}'"
    ]


def test_pointcloud_means_pointcloud2():
    cls = resolve_handler("lidar", "PointCloud", "", "sensors_node")
    assert cls.ros_message_type == "sensor_msgs/msg/PointCloud2"


def test_an_unknown_type_is_answered_with_the_closest_known_one():
    with pytest.raises(SensorsConfigurationError) as info:
        resolve_handler("s", "sensor_msgs/msg/LaserScann", "", "sensors_node")
    message = str(info.value)
    assert "sensors_node.s.type = 'sensor_msgs/msg/LaserScann'" in message
    assert "Did you mean 'sensor_msgs/msg/LaserScan'?" in message


def test_the_sensors_node_warns_once_per_sensor_with_a_short_name(caplog):
    manager = SensorsManager()
    params = DictParameters(
        {"sensors": ["laser"], "laser.topic": "/scan", "laser.type": "LaserScan"}
    )
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.configure(params, None, NavState(), clock=lambda: 0.0)
    assert type(manager.handler("laser")).__name__ == "LaserScanHandler"
    assert [r.getMessage() for r in caplog.records if "deprecated" in r.getMessage()] == [
        "sensors_node.laser.type = 'LaserScan' is deprecated: write the message type "
        "'sensor_msgs/msg/LaserScan'"
    ]
