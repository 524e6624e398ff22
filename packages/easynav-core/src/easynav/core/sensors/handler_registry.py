"""Which PerceptionHandler class serves a sensor: by its ``plugin`` or, if unset, its ``type``."""

from __future__ import annotations

from importlib import metadata

from easynav.core.sensors.errors import SensorsConfigurationError
from easynav.core.sensors.handlers import BUILTIN_HANDLERS
from easynav.core.sensors.perception_handler import PerceptionHandler, normalize_type_name

ENTRY_POINT_GROUP = "easynav.perception_handlers"


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


def resolve_handler(sensor_id: str, type_name: str, plugin: str, node_name: str) -> type:
    """The handler class for one sensor.

    ``plugin`` (a handler name such as ``"easynav_sensors/LaserScanHandler"``) wins; otherwise
    the handler whose ``ros_message_type`` is ``type_name`` (built-ins preferred, then plugins;
    two plugins for one type need ``plugin`` to choose). Raises
    :class:`SensorsConfigurationError` naming ``<node>.<sensor_id>.plugin`` or ``.type``.
    """
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
    raise SensorsConfigurationError(
        f"{parameter} = '{type_name}' has no perception handler. Supported types: "
        f"{', '.join(sorted(types))}"
    )
