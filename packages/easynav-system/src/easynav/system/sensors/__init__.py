"""The sensors manager and the perception handlers: ROS sensor topics into NavState perceptions.

Each configured sensor is a channel with a handler (a plugin of the ``easynav.perception_handlers``
group) that converts its messages into the kernel's perceptions (``easynav.common.sensors``); the
channel keeps its perception in NavState and expires it, the manager runs the channels and
publishes the fused cloud.
"""

from easynav.system.sensors.errors import PerceptionConversionError, SensorsConfigurationError
from easynav.system.sensors.perception_handler import PerceptionHandler
from easynav.system.sensors.sensor_channel import SensorChannel
from easynav.system.sensors.sensors_manager import SensorsManager

__all__ = [
    "PerceptionConversionError",
    "PerceptionHandler",
    "SensorChannel",
    "SensorsConfigurationError",
    "SensorsManager",
]
