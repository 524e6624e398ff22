"""sensors_node's parameters, declared once (read by SensorsManager and SensorChannel, tabled in
the README)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from easynav.core.plugins.declarations import Param, ParameterValueError, read_parameters
from easynav.system.sensors.errors import SensorsConfigurationError

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


def read_sensor_parameters(
    declarations: Any,
    params: Any,
    node_name: str,
    prefix: str = "",
    warn: Callable[[str], None] | None = None,
) -> Any:
    """The values of ``declarations`` under ``prefix`` (see
    :func:`~easynav.core.plugins.declarations.read_parameters`). Configuring thread.

    Raises :class:`~easynav.system.sensors.errors.SensorsConfigurationError` naming the
    parameter with the node prefix (``sensors_node.forget_time``), as the user writes it in the
    params file.
    """
    try:
        return read_parameters(declarations, params, prefix, warn=warn)
    except ParameterValueError as exc:
        raise SensorsConfigurationError(f"{node_name}.{exc}") from None
