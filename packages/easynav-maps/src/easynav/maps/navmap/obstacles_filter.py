"""ObstaclesFilter (easynav_navmap_maps_manager/NavMapMapsManager/ObstaclesFilter)."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.navmap.navmap import FREE_SPACE, LETHAL_OBSTACLE, NavMap
from easynav.maps.navmap.navmap_filter import NavMapFilter

#: The original's constants (ObstacleFilter.cpp): ±10 m xy around each sensor, 0.3 m voxels
#: and columns, 0.2 m height bins, 0.25 m height span.
RANGE_XY = 10.0
VOXEL_XY = 0.30
VOXEL_Z = 0.20
HEIGHT_THRESHOLD = 0.25
#: The layer of a NavMap converted from an occupancy grid that holds the grid's cells (254 where
#: it was occupied): its obstacles are static obstacles.
STATIC_LAYER = "occupancy"


def obstacle_columns(points: np.ndarray) -> np.ndarray:
    """(K, 3) query points of the obstacle columns of ``points`` (map frame), as the original.

    Points are binned in ``VOXEL_XY`` xy columns (``floor(x / 0.3)``) and ``VOXEL_Z`` height
    bins; a column is an obstacle when it spans more than 2 distinct height bins or more than
    ``HEIGHT_THRESHOLD`` from its lowest to its highest point. Its query point is the column's
    xy centre at the height of its highest point. Vectorised.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    points = points[np.isfinite(points).all(axis=1)]
    if len(points) == 0:
        return np.zeros((0, 3))
    ix = np.floor(points[:, 0] / VOXEL_XY).astype(np.int64)
    iy = np.floor(points[:, 1] / VOXEL_XY).astype(np.int64)
    iz = np.floor(points[:, 2] / VOXEL_Z).astype(np.int64)
    cols, col_of = np.unique(np.column_stack([ix, iy]), axis=0, return_inverse=True)
    col_of = col_of.reshape(-1)
    n = len(cols)
    zmax = np.full(n, -np.inf)
    zmin = np.full(n, np.inf)
    np.maximum.at(zmax, col_of, points[:, 2])
    np.minimum.at(zmin, col_of, points[:, 2])
    distinct = np.unique(np.column_stack([col_of, iz]), axis=0)
    bins = np.bincount(distinct[:, 0], minlength=n)
    obstacle = (bins > 2) | (zmax - zmin > HEIGHT_THRESHOLD)
    centre = (cols[obstacle] + 0.5) * VOXEL_XY
    return np.column_stack([centre, zmax[obstacle]])


class ObstaclesFilter(NavMapFilter):
    """Marks the NavCels under perceived obstacles lethal (254) in the layer ``obstacles``.

    As the original (no parameters): each cycle the uint8 layer ``obstacles`` is cleared to 0;
    the valid ungrouped :class:`PointPerception` points within ±10 m in x and y of their sensor
    are downsampled to 0.3 m voxels and fused into the map frame; :func:`obstacle_columns`
    gives the columns tall enough to be obstacles; each column's top point is located on the
    mesh (:meth:`NavMap.locate`: the surface nearest in height along the vertical, which is what
    the original's ``locate_navcel`` returns — its 0.5 m ``height_eps`` gates only its hint
    shortcut) and that NavCel set to 254. Without perceptions only the static obstacles are
    marked (a throttled warning).

    Not in the original: the lethal NavCels of the layer ``occupancy`` (:data:`STATIC_LAYER`, the
    walls of a NavMap converted from a map_server grid) are marked too, before the perceptions,
    like Nav2's static layer under its obstacle layer. The original clears the layer to 0, so
    its planner, which reads ``inflated_obstacles`` or ``obstacles`` only, planned through the
    grid's walls unless a 3D sensor saw them: a 2D laser never marks a column (its points span
    one height), and in the integration matrix the NavMap stack drove into the first wall of
    the home world. A mesh loaded as it is has no ``occupancy`` layer: its walls are holes.

    Thread contract: as :class:`NavMapFilter` (non-RT thread). TF failures skip the perception
    with a warning (PointPerceptionsOps), they never raise.
    """

    PARAMETERS = ()
    LAYER_NAME = "obstacles"

    def __init__(self) -> None:
        super().__init__()
        self._throttle = WarningThrottle(period=5.0)

    def update(self, nav_state: NavState, navmap: NavMap) -> None:
        """Rewrite the ``obstacles`` layer of ``navmap`` in place. Non-RT thread."""
        perceptions = nav_state.get_no_group(PointPerception)
        if not perceptions:
            self._throttle.warn(
                self.logger, "no-perceptions", f"{self.plugin_name}: no point perceptions"
            )
        layer = navmap.layer_clear(self.LAYER_NAME, FREE_SPACE, np.uint8)
        if navmap.has_layer(STATIC_LAYER):
            layer[navmap.layer(STATIC_LAYER) == LETHAL_OBSTACLE] = LETHAL_OBSTACLE
        if not perceptions:
            return
        buffer = get_tf_buffer(self.context.namespace)
        ops = PointPerceptionsOps(perceptions, buffer, self.logger)
        ops.filter((-RANGE_XY, -RANGE_XY, math.nan), (RANGE_XY, RANGE_XY, math.nan))
        ops.downsample(VOXEL_XY).fuse(buffer.get_tf_info().map_frame)
        queries = obstacle_columns(ops.as_points())
        if len(queries) == 0:
            return
        cids, _ = navmap.locate(queries)
        layer[cids[cids >= 0]] = LETHAL_OBSTACLE
