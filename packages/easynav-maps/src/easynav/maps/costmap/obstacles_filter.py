"""ObstaclesFilter (easynav_costmap_maps_manager/CostmapMapsManager/ObstaclesFilter)."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import ExtrapolationError, TransformError, get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import LETHAL_OBSTACLE, Costmap2D
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.costmap.costmap_filter import CostmapFilter
from easynav.maps.costmap.keys import MAP_OBSTACLE_BOUNDS, MAP_TIME
from easynav.maps.ray_casting import NOT_MARKED, clear_along_rays


class ObstaclesFilter(CostmapFilter):
    """Marks the cells of the perceived points lethal (254); clears cells a laser saw free.

    As the original: every valid ungrouped :class:`PointPerception`, downsampled to the map
    resolution, transformed into the map frame (the latest transform when the one at its stamp
    is missing), points with ``min_z <= z`` kept; each in-bounds point's cell becomes 254;
    ``map.obstacle_bounds`` covers the marked cells and ``map_time`` becomes the newest stamp of
    the perceptions used.

    Beyond the original, marks are remembered per cell with the time they were seen:

    - ``persistence`` (s): how long a mark stays after it was last seen. 0 (default) is the
      original: only the points of the perceptions in NavState now are obstacles.
    - ``clearing``: each beam, from the sensor's origin (its frame's origin in the map frame) to
      its point, removes the marks older than the beam on the cells it crossed (up to
      ``raytrace_max_range``), so an obstacle that went away (a person who walked on) leaves no
      ghost: neither in the memory (``persistence`` > 0) nor from an older perception of another
      sensor (a slow camera seeing what the laser already sees through). Marks of the static map
      (``map.base``) are never cleared.

    Thread contract: as :class:`CostmapFilter` (non-RT thread). TF failures skip the perception
    with a throttled warning, they never raise.
    """

    PARAMETERS = (
        Param("min_z", 0.1, "points at or above this height (map frame) are obstacles", "m"),
        Param(
            "persistence", 0.0,
            "how long a mark stays after last seen (0: the original, only current points)", "s",
            ge=0.0,
        ),
        Param("clearing", True, "laser beams clear the older marks on the cells they cross"),
        Param(
            "raytrace_max_range", 5.0, "beams clear cells up to this distance from the sensor",
            "m", gt=0.0,
        ),
    )
    READS = ()
    WRITES = (MAP_OBSTACLE_BOUNDS, MAP_TIME)

    def __init__(self) -> None:
        super().__init__()
        self._marks: np.ndarray | None = None
        self._marked = np.empty(0, dtype=np.int64)
        self._grid: tuple | None = None
        self._throttle = WarningThrottle(period=5.0)

    def on_initialize(self) -> None:
        self._marks = None
        self._marked = np.empty(0, dtype=np.int64)
        self._grid = None
        # Compile the ray caster (or load it from numba's cache) now, not in the first cycle.
        clear_along_rays(np.zeros((2, 2)), (0, 0), np.array([1]), np.array([1]), 1.0, 2.0)

    @property
    def marks(self) -> np.ndarray | None:
        """Per-cell time (s) of the last mark, ``-inf`` where none (a view: do not modify)."""
        return self._marks

    def _marks_for(self, costmap: Costmap2D) -> np.ndarray:
        grid = (costmap.data.shape, costmap.resolution, costmap.origin_x, costmap.origin_y)
        if self._marks is None or grid != self._grid:
            self._marks = np.full(costmap.data.shape, NOT_MARKED, dtype=np.float64)
            self._marked = np.empty(0, dtype=np.int64)
            self._grid = grid
        return self._marks

    def update(self, nav_state: NavState, costmap: Costmap2D) -> None:
        """Mark and clear ``costmap`` in place. Non-RT thread.

        The work is proportional to the points and the marked cells, not to the map: the marked
        cells are kept as a list of flat indices beside the per-cell times.
        """
        perceptions = nav_state.get_no_group(PointPerception)
        if not perceptions:
            self._throttle.warn(
                self.logger, "no-perceptions", f"{self.plugin_name}: no point perceptions"
            )
        marks = self._marks_for(costmap)
        flat_marks = marks.reshape(-1)  # a view: marks is C-contiguous
        persistence = self.params.persistence
        if persistence == 0.0:  # the original: only this cycle's points
            flat_marks[self._marked] = NOT_MARKED
            self._marked = np.empty(0, dtype=np.int64)
        buffer = get_tf_buffer(self.context.namespace)
        map_frame = buffer.get_tf_info().map_frame
        newest = -math.inf
        ordered = sorted(
            ((label, p) for label, p in perceptions.items() if p.valid),
            key=lambda item: item[1].stamp,
        )
        added = [self._marked]
        for label, perception in ordered:
            ops = PointPerceptionsOps({label: perception}, buffer, self.logger)
            ops.downsample(costmap.resolution).fuse(map_frame)
            ops.filter((math.nan, math.nan, self.params.min_z), (math.nan, math.nan, math.nan))
            points = ops.as_points()
            if len(points) == 0:
                continue
            stamp = float(perception.stamp)
            newest = max(newest, stamp)
            ix, iy = costmap.world_to_cell(points[:, 0], points[:, 1])
            if self.params.clearing:
                origin = self._sensor_origin(buffer, perception, map_frame)
                if origin is not None:
                    ox, oy = costmap.world_to_cell(origin[0], origin[1])
                    clear_along_rays(
                        marks, (int(ox), int(oy)), ix, iy, stamp,
                        self.params.raytrace_max_range / costmap.resolution,
                    )
            inside = costmap.in_bounds(ix, iy)
            flat = iy[inside] * costmap.width + ix[inside]
            flat_marks[flat] = np.maximum(flat_marks[flat], stamp)
            added.append(flat)
        marked = np.unique(np.concatenate(added)) if len(added) > 1 else self._marked
        times = flat_marks[marked]
        if persistence > 0.0:
            now = max(float(self.now()), newest)
            expired = times < now - persistence
            flat_marks[marked[expired]] = NOT_MARKED
            times = np.where(expired, NOT_MARKED, times)
        self._marked = marked = marked[times > NOT_MARKED]  # cleared or expired: gone
        if newest > -math.inf:
            nav_state.set(MAP_TIME, newest)
        if len(marked) == 0:
            return
        rows, cols = np.divmod(marked, costmap.width)
        costmap.data[rows, cols] = LETHAL_OBSTACLE  # whatever the array's memory layout
        (x0, x1), (y0, y1) = costmap.cell_to_world(
            np.array([cols.min(), cols.max()]), np.array([rows.min(), rows.max()])
        )
        self.extend_obstacle_bounds(nav_state, (float(x0), float(y0), float(x1), float(y1)))

    def _sensor_origin(
        self, buffer, perception: PointPerception, map_frame: str
    ) -> tuple[float, float] | None:
        """The sensor frame's origin in the map frame, or None (no transform: no clearing)."""
        frame = perception.frame_id
        if not frame or frame.lstrip("/") == map_frame.lstrip("/"):
            return None  # points given in the map frame carry no sensor position
        try:
            try:
                _, values = buffer.lookup_transform_values(map_frame, frame, perception.stamp)
            except ExtrapolationError:
                _, values = buffer.lookup_transform_values(map_frame, frame, None)
        except TransformError:
            return None  # the fuse step already warned about this perception
        if not (math.isfinite(values[0]) and math.isfinite(values[1])):
            return None
        return float(values[0]), float(values[1])
