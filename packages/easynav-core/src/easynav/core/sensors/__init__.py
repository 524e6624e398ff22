"""Sensors: perceptions, perception handlers, the sensors manager and point operations.

``PointPerception`` (LaserScan and PointCloud2 sensors) and :class:`PointPerceptionsOps` are the
cross-team contract: plugins read ``nav_state.get_no_group(PointPerception)`` and process it with
``PointPerceptionsOps(...).fuse(...).filter(...).downsample(...).as_points()``.
"""

from easynav.core.sensors.point_perception import PointPerception
from easynav.core.sensors.point_perceptions_ops import PointPerceptionsOps
from easynav.core.sensors.voxel_grid import voxel_downsample, voxel_downsample_indices

__all__ = [
    "PointPerception",
    "PointPerceptionsOps",
    "voxel_downsample",
    "voxel_downsample_indices",
]
