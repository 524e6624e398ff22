"""sensors_node's parameters, declared once (read by SensorsManager, tabled in the README)."""

from __future__ import annotations

from easynav.core.plugins.declarations import Param

FORGET_TIME = Param(
    "forget_time", 1.0, "a perception older than this is marked invalid", "s", gt=0.0,
    dynamic=False,
)
SENSOR_IDS = Param(
    "sensors", [], "sensor ids; each has <id>.topic and <id>.type", type="str[]", dynamic=False
)
#: Each sensor's own, under ``<id>.`` (a handler may declare more).
SENSOR_PARAMETERS = (
    Param("topic", "", "topic of the sensor (required)", dynamic=False),
    Param("type", "", "ROS message type, pkg/msg/Type", dynamic=False),
    Param("group", "", "optional NavState group", dynamic=False),
    Param("plugin", "", "optional perception handler plugin", dynamic=False),
)
#: sensors_node's own parameters.
SENSORS_NODE_PARAMETERS = (FORGET_TIME, SENSOR_IDS)
