"""SensorState: what the sensors manager knows about one configured sensor."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from easynav.system.sensors.perception_handler import PerceptionHandler


@dataclass(slots=True, eq=False)
class SensorState:
    """Configuration, handler, subscription and the perception last stored for one sensor.

    ``stored`` is the object the manager last wrote under ``sensor_id`` (None before any data);
    ``delayed`` is True when the last message was already older than ``forget_time``.

    Thread contract: owned by :class:`~easynav.system.sensors.sensors_manager.SensorsManager`,
    which touches it under its lock.
    """

    sensor_id: str
    topic: str
    type_name: str
    group: str
    handler: PerceptionHandler
    subscription: Any = None
    stored: Any = None
    delayed: bool = False
    messages: int = 0
    rejected: int = 0
