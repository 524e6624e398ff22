"""FootprintChecker: is a circular robot at (x, y) clear of the obstacles of a Costmap2D?"""

from __future__ import annotations

import math

import cv2
import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, NO_INFORMATION, Costmap2D


class FootprintChecker:
    """Collision test of a disc of radius ``radius`` on a :class:`Costmap2D`.

    A cell is an obstacle when its cost is ``>= obstacle_cost`` (254, lethal, by default);
    unknown cells (255) are obstacles unless ``allow_unknown``; the area beyond the map edge is
    an obstacle. A position is **free** when no obstacle cell centre lies within ``radius`` of
    it. The test is conservative: the clearance of a position is taken as the distance between
    the centre of its cell and the nearest obstacle cell centre (OpenCV's exact Euclidean
    distance transform) minus half a cell diagonal, so a free position never has an obstacle
    cell centre within ``radius`` (the rule the tests check directly).

    Free regions (:meth:`connected`, :meth:`region_extent`) are computed on first use: threads
    racing there compute equal results, one of which is kept.

    Thread contract: immutable after construction (but for that cache); any thread may call it.
    Exceptions: :class:`ValueError` for a radius or cost out of range or an empty costmap.
    """

    def __init__(
        self,
        costmap: Costmap2D,
        radius: float,
        obstacle_cost: int = LETHAL_OBSTACLE,
        allow_unknown: bool = False,
    ) -> None:
        radius = float(radius)
        if not math.isfinite(radius) or radius < 0.0:
            raise ValueError(f"footprint radius = {radius} must be finite and >= 0")
        if not 1 <= int(obstacle_cost) <= 255:
            raise ValueError(f"obstacle_cost = {obstacle_cost} must be in [1, 255]")
        if costmap.width == 0 or costmap.height == 0:
            raise ValueError("the costmap is empty (0 cells)")
        self.costmap = costmap
        self.obstacle_cost = int(obstacle_cost)
        self.allow_unknown = bool(allow_unknown)
        data = costmap.data
        obstacle = data >= self.obstacle_cost
        if self.allow_unknown:
            obstacle &= data != NO_INFORMATION
        self.obstacle = obstacle
        # A ring of obstacle cells around the map keeps the robot inside it.
        free = np.pad(~obstacle, 1, constant_values=False).astype(np.uint8)
        distance = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)[1:-1, 1:-1]
        res = costmap.resolution
        # Any point of a cell is within half a diagonal of its centre.
        self.clearance = distance.astype(np.float64) * res - res * math.sqrt(0.5)
        self._ox, self._oy, self._inv = costmap.origin_x, costmap.origin_y, 1.0 / res
        self._w, self._h = costmap.width, costmap.height
        self._set_radius(radius)

    def _set_radius(self, radius: float) -> None:
        self.radius = radius
        self.free = self.clearance > radius
        # Plain bytes rows for the scalar test OMPL calls per state (faster than numpy scalars).
        self._free_rows = [bytes(row) for row in self.free.astype(np.uint8)]
        self._regions: tuple[np.ndarray, np.ndarray] | None = None

    def with_radius(self, radius: float) -> FootprintChecker:
        """The same map with another disc radius (the distance transform is shared)."""
        radius = float(radius)
        if not math.isfinite(radius) or radius < 0.0:
            raise ValueError(f"footprint radius = {radius} must be finite and >= 0")
        other = object.__new__(FootprintChecker)
        for name in (
            "costmap", "obstacle_cost", "allow_unknown", "obstacle", "clearance",
            "_ox", "_oy", "_inv", "_w", "_h",
        ):
            setattr(other, name, getattr(self, name))
        other._set_radius(radius)
        return other

    def is_free(self, x: float, y: float) -> bool:
        """Whether the disc at ``(x, y)`` is clear (False off the map or for non-finite input)."""
        fx = (x - self._ox) * self._inv
        fy = (y - self._oy) * self._inv
        if not (0.0 <= fx < self._w and 0.0 <= fy < self._h):  # NaN fails too
            return False
        return self._free_rows[int(fy)][int(fx)] == 1

    @property
    def origin_x(self) -> float:
        """The costmap's origin x (m)."""
        return self._ox

    @property
    def origin_y(self) -> float:
        """The costmap's origin y (m)."""
        return self._oy

    @property
    def cells_per_m(self) -> float:
        """``1 / resolution``."""
        return self._inv

    def is_on_map(self, x: float, y: float) -> bool:
        """Whether ``(x, y)`` is on the costmap (False for non-finite input)."""
        fx = (x - self._ox) * self._inv
        fy = (y - self._oy) * self._inv
        return 0.0 <= fx < self._w and 0.0 <= fy < self._h

    def are_free(self, xy: np.ndarray) -> np.ndarray:
        """Vectorised :meth:`is_free` of an ``(N, 2)`` array of positions."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        finite = np.isfinite(xy).all(axis=1)
        ix, iy = self.costmap.world_to_cell(*np.where(finite[:, None], xy, 0.0).T)
        inside = self.costmap.in_bounds(ix, iy) & finite
        result = np.zeros(len(xy), dtype=bool)
        result[inside] = self.free[iy[inside], ix[inside]]
        return result

    def polyline_free(self, xy: np.ndarray, step: float | None = None) -> tuple[bool, int]:
        """Whether the straight segments joining ``xy`` (``(N, 2)``) are free, sampled every
        ``step`` (half a cell by default). Returns ``(ok, index)``: ``index`` is the first
        vertex whose outgoing segment (or itself) is not free, -1 when all are."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        if len(xy) == 0:
            return True, -1
        step = 0.5 * self.costmap.resolution if step is None else float(step)
        if not self.is_free(float(xy[0, 0]), float(xy[0, 1])):
            return False, 0
        for i in range(len(xy) - 1):
            a, b = xy[i], xy[i + 1]
            n = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
            t = np.arange(1, n + 1, dtype=float)[:, None] / n
            if not self.are_free(a + t * (b - a)).all():
                return False, i
        return True, -1

    # -- free regions -----------------------------------------------------------------------------
    def _labels(self) -> tuple[np.ndarray, np.ndarray]:
        """``(labels, boxes)``: each free cell's region (8-connected free cells; 0: not free) and
        each region's cell box ``(ix0, iy0, width, height)``, computed on first use."""
        if self._regions is None:
            _, labels, stats, _ = cv2.connectedComponentsWithStats(
                self.free.astype(np.uint8), connectivity=8, ltype=cv2.CV_32S
            )
            self._regions = (labels, stats[:, :4])
        return self._regions

    def region_labels(self) -> np.ndarray:
        """Each cell's free region (``(height, width)``, 0 where the disc is not free); see
        :meth:`region_label`."""
        return self._labels()[0]

    def region_label(self, x: float, y: float) -> int:
        """The free region of the disc at ``(x, y)`` (0 when it is not free).

        A region is a set of free cells joined through edges or corners: a robot moving
        continuously between two free positions passes only free cells, each next to the one
        before, so positions in different regions are joined by no free motion at all.
        """
        if not self.is_free(x, y):
            return 0
        labels, _ = self._labels()
        return int(labels[int((y - self._oy) * self._inv), int((x - self._ox) * self._inv)])

    def connected(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """Whether free positions ``a`` and ``b`` lie in the same free region (False when
        either is not free): without it no motion of the disc joins them."""
        label = self.region_label(*a)
        return label != 0 and label == self.region_label(*b)

    def region_extent(self, x: float, y: float) -> tuple[float, float, float, float] | None:
        """``(x0, y0, x1, y1)`` (m): the box of the cells of the free region of ``(x, y)``,
        a cell wider on every side (within the map); None when it is not free. Every free
        motion from ``(x, y)`` stays inside it. The extra cell: a point is put in its cell by
        flooring, so a point of an edge cell may lie a rounding error outside the cells' exact
        box (-7.55 in a cell whose edge computes as -7.549999999999999), and OMPL refuses a
        start or goal outside its bounds."""
        label = self.region_label(x, y)
        if label == 0:
            return None
        ix0, iy0, width, height = (int(v) for v in self._labels()[1][label])
        res = self.costmap.resolution
        ix1, iy1 = min(ix0 + width + 1, self._w), min(iy0 + height + 1, self._h)
        ix0, iy0 = max(ix0 - 1, 0), max(iy0 - 1, 0)
        return (self._ox + ix0 * res, self._oy + iy0 * res,
                self._ox + ix1 * res, self._oy + iy1 * res)

    def nearest_obstacle_distance(self, x: float, y: float) -> float:
        """Exact distance (m) from ``(x, y)`` to the nearest obstacle cell centre (inf if none);
        a brute-force reference for tests and reports, not for hot paths."""
        iy, ix = np.nonzero(self.obstacle)
        if len(ix) == 0:
            return math.inf
        cx, cy = self.costmap.cell_to_world(ix, iy)
        return float(np.min(np.hypot(cx - x, cy - y)))
