"""ROS sensor messages -> perceptions' numpy data, vectorised. ROS messages stop here."""

from easynav.system.sensors.converters.detections import detections_from_msg
from easynav.system.sensors.converters.image import image_from_msg
from easynav.system.sensors.converters.imu import imu_from_msg
from easynav.system.sensors.converters.laser_scan import LaserScanConverter, ScanConversionStats
from easynav.system.sensors.converters.nav_sat_fix import gnss_from_msg
from easynav.system.sensors.converters.point_cloud2 import (
    point_cloud2_from_points,
    points_from_point_cloud2,
)
from easynav.system.sensors.converters.stamps import stamp_to_seconds

__all__ = [
    "LaserScanConverter",
    "ScanConversionStats",
    "detections_from_msg",
    "gnss_from_msg",
    "image_from_msg",
    "imu_from_msg",
    "point_cloud2_from_points",
    "points_from_point_cloud2",
    "stamp_to_seconds",
]
