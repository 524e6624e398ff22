"""The sensors manager and the perception handlers: ROS sensor topics into NavState perceptions.

Each configured sensor has a handler (a plugin of the ``easynav.perception_handlers`` group) that
converts its messages into the kernel's perceptions (``easynav.core.sensors``); the manager keeps
them in NavState, expires old ones and publishes the fused cloud.
"""

from easynav.system.sensors.errors import PerceptionConversionError, SensorsConfigurationError
from easynav.system.sensors.perception_handler import PerceptionHandler
from easynav.system.sensors.sensors_manager import SensorsManager

__all__ = [
    "PerceptionConversionError",
    "PerceptionHandler",
    "SensorsConfigurationError",
    "SensorsManager",
]
