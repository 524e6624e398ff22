"""PerceptionHandler: the plugin that turns one sensor's ROS messages into perceptions."""

from __future__ import annotations

import importlib
import logging
from abc import ABC, abstractmethod
from typing import Any, ClassVar

from easynav.core.warning_throttle import WarningThrottle


def normalize_type_name(type_name: str) -> str:
    """``"sensor_msgs/LaserScan"`` or ``"sensor_msgs/msg/LaserScan"`` -> the latter."""
    parts = [p for p in type_name.strip().split("/") if p]
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return "/".join(parts)


def import_message_class(type_name: str) -> type:
    """The Python class of a ROS message type name such as ``"sensor_msgs/msg/LaserScan"``.

    Raises ``ImportError`` naming the type and the Python package to install when the message
    package is missing, ``ValueError`` for a malformed name.
    """
    parts = normalize_type_name(type_name).split("/")
    if len(parts) != 3 or parts[1] != "msg":
        raise ValueError(f"'{type_name}' is not a ROS message type name like 'pkg/msg/Type'")
    package, _, name = parts
    try:
        module = importlib.import_module(f"{package}.msg")
    except ImportError as exc:
        raise ImportError(
            f"message package '{package}' for {type_name} is not installed in this Python "
            f"environment ({exc}); install it (e.g. pip install ros-jazzy-"
            f"{package.replace('_', '-')}) or build it as a wheel"
        ) from exc
    cls = getattr(module, name, None)
    if cls is None:
        raise ImportError(f"message package '{package}' has no message '{name}' ({type_name})")
    return cls


class PerceptionHandler(ABC):
    """Base of the perception handlers (entry-point group ``easynav.perception_handlers``).

    A subclass sets ``ros_message_type`` (full type name, e.g. ``"sensor_msgs/msg/LaserScan"``)
    and ``perception_type`` (the class stored in NavState), and implements
    :meth:`to_perception`. The sensors manager creates one handler object per sensor, so a
    handler may keep per-sensor state (e.g. cached beam angles). Every perception type has
    ``stamp``, ``frame_id``, ``valid`` and ``new_data``; the manager sets the last two.

    Thread contract: :meth:`configure` runs in the configuring thread; :meth:`to_perception` in
    the thread that spins the sensor subscription (the RT loop's executor).
    Exceptions: :meth:`to_perception` raises
    :class:`~easynav.system.sensors.errors.PerceptionConversionError` for a malformed message (the
    manager warns naming the sensor and keeps running); :meth:`message_class` raises
    ``ImportError`` naming the missing message package.
    """

    ros_message_type: ClassVar[str] = ""
    perception_type: ClassVar[type] = object

    def __init__(self) -> None:
        self.logger: Any = logging.getLogger("easynav.sensors")
        self._throttle = WarningThrottle(period=10.0)

    def message_class(self) -> type:
        """The ROS message class to subscribe with (imported on demand)."""
        return import_message_class(self.ros_message_type)

    def configure(self, sensor_id: str, parameters: Any, node: Any) -> None:  # noqa: B027
        """Read handler-specific parameters ``<sensor_id>.<name>`` (none by default)."""

    @abstractmethod
    def to_perception(self, msg: Any, sensor_id: str) -> Any:
        """The perception of one message (``valid`` and ``new_data`` left True)."""

    def warn(self, sensor_id: str, text: str, kind: str = "") -> None:
        """A warning naming the sensor, at most once per 10 s per sensor and ``kind``."""
        self._throttle.warn(self.logger, (sensor_id, kind), f"Sensor '{sensor_id}': {text}")
