"""Which PerceptionHandler class serves a sensor: by its ``plugin`` or, if unset, its ``type``."""

from __future__ import annotations

import difflib
from collections.abc import Callable
from importlib import metadata

from easynav.system.sensors.errors import SensorsConfigurationError
from easynav.system.sensors.handlers import BUILTIN_HANDLERS
from easynav.system.sensors.perception_handler import PerceptionHandler, normalize_type_name

ENTRY_POINT_GROUP = "easynav.perception_handlers"

#: Short type names that older params files of the original use (``type: PointCloud``); the
#: original's sensors node accepted them. Deprecated aliases of the full message types.
SHORT_TYPE_NAMES = {
    "LaserScan": "sensor_msgs/msg/LaserScan",
    "PointCloud": "sensor_msgs/msg/PointCloud2",
    "PointCloud2": "sensor_msgs/msg/PointCloud2",
    "Image": "sensor_msgs/msg/Image",
    "Imu": "sensor_msgs/msg/Imu",
    "NavSatFix": "sensor_msgs/msg/NavSatFix",
    "GNSS": "sensor_msgs/msg/NavSatFix",
    "Odometry": "nav_msgs/msg/Odometry",
    "Detection3DArray": "vision_msgs/msg/Detection3DArray",
}


def expand_short_type_name(
    type_name: str, parameter: str, warn: Callable[[str], None] | None = None
) -> str:
    """The full message type of a short alias (``LaserScan``), with a deprecation warning
    through ``warn``; any other name unchanged."""
    full = SHORT_TYPE_NAMES.get(type_name.strip())
    if full is None:
        return type_name
    if warn is not None:
        warn(f"{parameter} = '{type_name}' is deprecated: write the message type '{full}'")
    return full


def _load(name: str, target: metadata.EntryPoint | type, parameter: str) -> type:
    if isinstance(target, type):
        cls = target
    else:
        try:
            cls = target.load()
        except Exception as exc:
            raise SensorsConfigurationError(
                f"{parameter}: perception handler '{name}' ({target.value}) failed to import: "
                f"{type(exc).__name__}: {exc}"
            ) from exc
    if not (isinstance(cls, type) and issubclass(cls, PerceptionHandler)):
        raise SensorsConfigurationError(
            f"{parameter}: perception handler '{name}' is not a PerceptionHandler subclass"
        )
    return cls


def available_handlers() -> dict[str, metadata.EntryPoint | type]:
    """Handler name -> entry point (or built-in class), entry points of plugins included.

    The built-ins are always present, also when the editable install has not been refreshed
    since their entry points were added.
    """
    found: dict[str, metadata.EntryPoint | type] = dict(BUILTIN_HANDLERS)
    for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
        if ep.name not in BUILTIN_HANDLERS:
            found[ep.name] = ep
    return found


def resolve_handler(
    sensor_id: str,
    type_name: str,
    plugin: str,
    node_name: str,
    warn: Callable[[str], None] | None = None,
) -> type:
    """The handler class for one sensor.

    ``plugin`` (a handler name such as ``"easynav_sensors/LaserScanHandler"``) wins; otherwise
    the handler whose ``ros_message_type`` is ``type_name`` (built-ins preferred, then plugins;
    two plugins for one type need ``plugin`` to choose). A short type name of the original
    (``LaserScan``, ``PointCloud``) stands for its message type, with a warning through ``warn``.
    Raises :class:`SensorsConfigurationError` naming ``<node>.<sensor_id>.plugin`` or ``.type``
    (an unknown type with the closest known one).
    """
    if type_name:
        type_name = expand_short_type_name(type_name, f"{node_name}.{sensor_id}.type", warn)
    handlers = available_handlers()
    wanted = normalize_type_name(type_name) if type_name else ""
    if plugin:
        parameter = f"{node_name}.{sensor_id}.plugin"
        target = handlers.get(plugin)
        if target is None:
            raise SensorsConfigurationError(
                f"{parameter}: unknown perception handler '{plugin}'. Installed: "
                f"{', '.join(sorted(handlers))}"
            )
        cls = _load(plugin, target, parameter)
        if wanted and normalize_type_name(cls.ros_message_type) != wanted:
            raise SensorsConfigurationError(
                f"{node_name}.{sensor_id}.type = '{type_name}' but {parameter} = '{plugin}' "
                f"handles {cls.ros_message_type}"
            )
        return cls
    parameter = f"{node_name}.{sensor_id}.type"
    if not wanted:
        raise SensorsConfigurationError(
            f"{parameter} is not set: give the sensor's ROS message type (e.g. "
            f"sensor_msgs/msg/LaserScan) or {node_name}.{sensor_id}.plugin"
        )
    for cls in BUILTIN_HANDLERS.values():
        if cls.ros_message_type == wanted:
            return cls
    matches = []
    types = {cls.ros_message_type for cls in BUILTIN_HANDLERS.values()}
    for name, target in handlers.items():
        if name in BUILTIN_HANDLERS:
            continue
        cls = _load(name, target, parameter)
        types.add(cls.ros_message_type)
        if normalize_type_name(cls.ros_message_type) == wanted:
            matches.append((name, cls))
    if len(matches) == 1:
        return matches[0][1]
    if matches:
        raise SensorsConfigurationError(
            f"{parameter} = '{type_name}' is handled by several plugins "
            f"({', '.join(n for n, _ in matches)}): choose one with {node_name}.{sensor_id}.plugin"
        )
    known = sorted(types | set(SHORT_TYPE_NAMES))
    close = difflib.get_close_matches(type_name.strip(), known, n=1, cutoff=0.5)
    hint = f" Did you mean '{close[0]}'?" if close else ""
    raise SensorsConfigurationError(
        f"{parameter} = '{type_name}' has no perception handler.{hint} Supported types: "
        f"{', '.join(sorted(types))}"
    )
