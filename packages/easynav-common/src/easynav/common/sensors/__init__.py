"""Perceptions: what the sensors give the plugins, and the operations on point sets.

``PointPerception`` (LaserScan and PointCloud2 sensors) and :class:`PointPerceptionsOps` are the
cross-team contract: plugins read ``nav_state.get_no_group(PointPerception)`` and process it with
``PointPerceptionsOps(...).fuse(...).filter(...).downsample(...).as_points()``. The runtime's
sensors manager (``easynav.system.sensors``) fills NavState with them from ROS topics; a script
can make them directly from numpy arrays.
"""

from easynav.common.sensors.detection import Detection
from easynav.common.sensors.detections_perception import DetectionsPerception
from easynav.common.sensors.gnss_perception import GNSSPerception
from easynav.common.sensors.image_perception import ImagePerception
from easynav.common.sensors.imu_perception import ImuPerception
from easynav.common.sensors.odometry_perception import OdometryPerception
from easynav.common.sensors.point_perception import PointPerception
from easynav.common.sensors.point_perceptions_ops import PointPerceptionsOps
from easynav.common.sensors.voxel_grid import voxel_downsample, voxel_downsample_indices

__all__ = [
    "Detection",
    "DetectionsPerception",
    "GNSSPerception",
    "ImagePerception",
    "ImuPerception",
    "OdometryPerception",
    "PointPerception",
    "PointPerceptionsOps",
    "voxel_downsample",
    "voxel_downsample_indices",
]
