"""The built-in perception handlers (registered in ``easynav.perception_handlers``)."""

from easynav.system.sensors.handlers.detection3d_array_handler import Detection3DArrayHandler
from easynav.system.sensors.handlers.image_handler import ImageHandler
from easynav.system.sensors.handlers.imu_handler import ImuHandler
from easynav.system.sensors.handlers.laser_scan_handler import LaserScanHandler
from easynav.system.sensors.handlers.nav_sat_fix_handler import NavSatFixHandler
from easynav.system.sensors.handlers.odometry_handler import OdometryHandler
from easynav.system.sensors.handlers.point_cloud2_handler import PointCloud2Handler

BUILTIN_HANDLERS: dict[str, type] = {
    "easynav_sensors/LaserScanHandler": LaserScanHandler,
    "easynav_sensors/PointCloud2Handler": PointCloud2Handler,
    "easynav_sensors/ImageHandler": ImageHandler,
    "easynav_sensors/ImuHandler": ImuHandler,
    "easynav_sensors/NavSatFixHandler": NavSatFixHandler,
    "easynav_sensors/OdometryHandler": OdometryHandler,
    "easynav_sensors/Detection3DArrayHandler": Detection3DArrayHandler,
}

__all__ = [
    "BUILTIN_HANDLERS",
    "Detection3DArrayHandler",
    "ImageHandler",
    "ImuHandler",
    "LaserScanHandler",
    "NavSatFixHandler",
    "OdometryHandler",
    "PointCloud2Handler",
]
