"""CollisionModel: which rollout poses of a cycle collide with the costmap's obstacles.

A pose collides when its centre is on an inscribed or lethal cell (or unknown space, or off
the map), as in Nav2's CostCritic, or when the robot's disc, widened by a margin, overlaps an
obstacle cell. The first test alone lets the robot touch obstacles: a cell is inscribed when
its centre is within the inscribed radius of an obstacle cell's centre, but the obstacle fills
its whole cell, so a robot centred on the nearest non-inscribed cell can reach it (seen between
the tb3_sandbox pillars: MPPI followed a path along a pillar's face with 0 to 5 cm to spare,
and with the localisation error it sometimes touched). The second test measures the distance
to the cells' squares, not their centres, and keeps ``margin`` in hand for the localisation
and the tracking errors.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.types import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)

#: How much nearer an obstacle than the robot is now a pose may be while the robot is already
#: within the margin (m): it may then move along the obstacle or away, not towards it. Without
#: it, a robot that drifted into the margin (a localisation jump) would find every candidate
#: colliding and stay blocked.
INSIDE_MARGIN_SLACK = 0.01

#: A robot the estimate puts over an obstacle must gain at least this much clearance per metre
#: it drives (at least 30 degrees away from the obstacle's face), until its disc is clear: it
#: may turn on the spot and get out, not slide along the obstacle nor come nearer.
ESCAPE_GAIN = 0.5

#: What a rollout getting out may fall short of :data:`ESCAPE_GAIN` by (m): sampled rollouts
#: that turn away creep forward a little while they turn (a rollout may slide 2 mm along the
#: obstacle; the robot, 4 cm/s at 20 Hz, at the same depth).
ESCAPE_TOLERANCE = 0.001

#: What a rollout getting out may come nearer than the robot is (m): rounding only (the start
#: is measured at the pose rounded to float32, as the rollouts are).
ESCAPE_ROUNDING = 1e-5


def rollout_costs(costmap: Costmap2D, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Costmap values (uint8) at the points ``(x, y)``; off the map: NO_INFORMATION."""
    ix = np.floor((x - np.float32(costmap.origin_x)) * np.float32(1.0 / costmap.resolution))
    iy = np.floor((y - np.float32(costmap.origin_y)) * np.float32(1.0 / costmap.resolution))
    ix = ix.astype(np.int32)
    iy = iy.astype(np.int32)
    inside = (ix >= 0) & (ix < costmap.width) & (iy >= 0) & (iy < costmap.height)
    np.clip(ix, 0, costmap.width - 1, out=ix)
    np.clip(iy, 0, costmap.height - 1, out=iy)
    costs = costmap.data[iy, ix]
    costs[~inside] = NO_INFORMATION
    return costs


def obstacle_cells(costmap_data: np.ndarray, unknown_is_obstacle: bool) -> np.ndarray:
    """Boolean mask of the cells that are obstacles: lethal, and unknown when asked."""
    mask = costmap_data == LETHAL_OBSTACLE
    if unknown_is_obstacle:
        mask |= costmap_data == NO_INFORMATION
    return mask


class ClearanceField:
    """Distance (m) from points to the nearest obstacle cell's square, near a centre point.

    Computed at the cell centres of a square window (``half_size`` around ``(cx, cy)``) by
    brute force over the cell offsets within ``cap`` (the distance from a centre to a cell
    square ``(dx, dy)`` cells away is ``hypot(max(|dx| - ½, 0), max(|dy| - ½, 0))`` cells),
    capped at ``cap``, and interpolated bilinearly between centres by :meth:`at`. Off the map
    counts as unknown space.

    Pure data; any thread. Exceptions: none.
    """

    def __init__(self, costmap: Costmap2D, cx: float, cy: float, half_size: float, cap: float,
                 unknown_is_obstacle: bool) -> None:
        res = float(costmap.resolution)
        self.resolution = res
        self.cap = float(cap)
        k = int(math.ceil(cap / res)) + 1
        self.i0 = int(math.floor((cx - half_size - costmap.origin_x) / res))
        self.j0 = int(math.floor((cy - half_size - costmap.origin_y) / res))
        i1 = int(math.floor((cx + half_size - costmap.origin_x) / res))
        j1 = int(math.floor((cy + half_size - costmap.origin_y) / res))
        width, height = max(i1 - self.i0 + 1, 2), max(j1 - self.j0 + 1, 2)
        self.origin = (float(costmap.origin_x), float(costmap.origin_y))
        # The obstacle mask of the window padded by k cells (off the map: unknown).
        padded = np.full((height + 2 * k, width + 2 * k), unknown_is_obstacle)
        pi0, pj0 = self.i0 - k, self.j0 - k
        si0, sj0 = max(pi0, 0), max(pj0, 0)
        si1 = min(pi0 + padded.shape[1], costmap.width)
        sj1 = min(pj0 + padded.shape[0], costmap.height)
        if si0 < si1 and sj0 < sj1:
            padded[sj0 - pj0:sj1 - pj0, si0 - pi0:si1 - pi0] = obstacle_cells(
                costmap.data[sj0:sj1, si0:si1], unknown_is_obstacle)
        distance = np.full((height, width), np.float32(cap), dtype=np.float32)
        offsets = []
        for dy in range(-k, k + 1):
            for dx in range(-k, k + 1):
                d = math.hypot(max(abs(dx) - 0.5, 0.0), max(abs(dy) - 0.5, 0.0)) * res
                if d < cap:
                    offsets.append((d, dx, dy))
        # Farthest first: each nearer offset overwrites, so every cell ends with its minimum.
        for d, dx, dy in sorted(offsets, reverse=True):
            view = padded[k + dy:k + dy + height, k + dx:k + dx + width]
            np.copyto(distance, np.float32(d), where=view)
        self.distance = distance
        self._padded = padded
        self._k = k
        self._offsets = np.array([(dx, dy) for _, dx, dy in offsets], dtype=np.int32)

    def exact(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The exact distance (float64, m, at most ``cap``) at the points ``(x, y)`` (1-D),
        by brute force over the cells within ``cap``: for a few points (a rollout)."""
        x = np.asarray(x, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        height, width = self.distance.shape
        u = (x - self.origin[0]) / self.resolution - self.i0  # in window cells
        v = (y - self.origin[1]) / self.resolution - self.j0
        iu = np.clip(np.floor(u).astype(np.int64), 0, width - 1)
        iv = np.clip(np.floor(v).astype(np.int64), 0, height - 1)
        cols = iu[:, None] + self._offsets[None, :, 0]  # S x offsets, window cells
        rows = iv[:, None] + self._offsets[None, :, 1]
        obstacle = self._padded[rows + self._k, cols + self._k]
        du = np.maximum(0.0, np.maximum(cols - u[:, None], u[:, None] - (cols + 1)))
        dv = np.maximum(0.0, np.maximum(rows - v[:, None], v[:, None] - (rows + 1)))
        d = np.where(obstacle, np.hypot(du, dv) * self.resolution, self.cap)
        return np.minimum(d.min(axis=1), self.cap) if d.shape[1] else np.full(len(x), self.cap)

    def below(self, x: np.ndarray, y: np.ndarray, threshold: float) -> np.ndarray:
        """Boolean array (the shape of ``x``): whether :meth:`at` is below ``threshold``.

        Interpolates only where the nearest cell centre's value is within half a cell diagonal
        of the threshold (the distance changes by at most that much between a point and its
        nearest centre): most rollout points are far from everything.
        """
        res = np.float32(1.0 / self.resolution)
        height, width = self.distance.shape
        iu = ((x - np.float32(self.origin[0])) * res).astype(np.int32) - np.int32(self.i0)
        iv = ((y - np.float32(self.origin[1])) * res).astype(np.int32) - np.int32(self.j0)
        np.clip(iu, 0, width - 1, out=iu)
        np.clip(iv, 0, height - 1, out=iv)
        near = self.distance[iv, iu] < np.float32(threshold + 0.71 * self.resolution)
        out = np.zeros(np.shape(x), dtype=bool)
        if near.any():
            out[near] = self.at(x[near], y[near]) < np.float32(threshold)
        return out

    def at(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The distance (float32, m, at most ``cap``) at the points ``(x, y)``; points beyond
        the window take the value at its edge."""
        res = np.float32(1.0 / self.resolution)
        u = (x - np.float32(self.origin[0])) * res - np.float32(self.i0 + 0.5)
        v = (y - np.float32(self.origin[1])) * res - np.float32(self.j0 + 0.5)
        height, width = self.distance.shape
        u = np.clip(u, 0.0, width - 1.0)
        v = np.clip(v, 0.0, height - 1.0)
        iu = np.minimum(u.astype(np.int32), width - 2)
        iv = np.minimum(v.astype(np.int32), height - 2)
        fu = u - iu
        fv = v - iv
        d = self.distance
        top = d[iv, iu] * (1.0 - fu) + d[iv, iu + 1] * fu
        bottom = d[iv + 1, iu] * (1.0 - fu) + d[iv + 1, iu + 1] * fu
        return (top * (1.0 - fv) + bottom * fv).astype(np.float32, copy=False)


def clearance_reference(costmap: Costmap2D, x: float, y: float,
                        unknown_is_obstacle: bool) -> float:
    """The exact distance (m) from ``(x, y)`` to the nearest obstacle cell's square, by brute
    force over every cell (for tests); ``inf`` without obstacles."""
    rows, cols = np.nonzero(obstacle_cells(costmap.data, unknown_is_obstacle))
    if rows.size == 0:
        return math.inf
    res = costmap.resolution
    u = (x - costmap.origin_x) / res
    v = (y - costmap.origin_y) / res
    du = np.maximum(0.0, np.maximum(cols - u, u - (cols + 1)))
    dv = np.maximum(0.0, np.maximum(rows - v, v - (rows + 1)))
    return float(np.hypot(du, dv).min() * res)


class CollisionModel:
    """The collision test of one MPPI cycle, for the CostCritic and the command's guard.

    A pose collides when the cell under its centre is inscribed, lethal or (with
    ``unknown_is_obstacle``) unknown or off the map, or when an obstacle cell is nearer than
    the threshold to its centre: ``radius + margin`` (``radius``: robot_geometry's), less
    where the robot cannot keep that much:

    - a path (``path_xy``, the points within ``reach``) that passes nearer lowers it to the
      path's clearance, never below ``radius``: the robot follows a tight plan without
      touching;
    - a robot already nearer (a localisation jump, an obstacle seen anew) is held to poses no
      nearer than it is then (``held``, the previous cycle's :attr:`held`), until it is out
      again; once its disc overlaps an obstacle, only rollouts that get out are clear
      (:data:`ESCAPE_GAIN`).

    Both less :data:`INSIDE_MARGIN_SLACK`. ``reach`` is the farthest a rollout can go from
    ``pose`` this cycle (m).

    Built once per cycle in the RT thread. Exceptions: none.
    """

    def __init__(self, costmap: Costmap2D, pose: tuple[float, float, float], reach: float,
                 radius: float, margin: float, unknown_is_obstacle: bool,
                 path_xy: np.ndarray | None = None, held: float | None = None) -> None:
        self.costmap = costmap
        self.unknown_is_obstacle = unknown_is_obstacle
        radius = max(radius, 0.0)
        self.radius = radius  # the inscribed radius of the CostCritic's local inflation
        keep = radius + max(margin, 0.0)
        self.field: ClearanceField | None = None
        self.threshold = 0.0
        self.held: float | None = None
        #: Whether the robot's disc overlaps an obstacle (by the estimate): only rollouts that
        #: get out are then clear (:data:`ESCAPE_GAIN`).
        self.escaping = False
        self._pose = (float(pose[0]), float(pose[1]))
        self._start = (0.0, 0.0)  # the robot's clearance: exact, and as the batch field has it
        if keep <= 0.0:
            return
        cap = keep + costmap.resolution
        self.field = ClearanceField(costmap, pose[0], pose[1], reach + costmap.resolution, cap,
                                    unknown_is_obstacle)
        limit = keep
        if path_xy is not None and len(path_xy):
            ahead = np.asarray(path_xy, dtype=np.float32)
            ahead = ahead[np.hypot(ahead[:, 0] - pose[0], ahead[:, 1] - pose[1]) <= reach]
            if len(ahead):
                along = float(self.field.at(ahead[:, 0], ahead[:, 1]).min())
                limit = min(limit, max(along - INSIDE_MARGIN_SLACK, radius))
        clearance = float(self.field.exact([pose[0]], [pose[1]])[0])
        inside = clearance - INSIDE_MARGIN_SLACK
        if inside < limit:
            # Within the limit: held to where it is. The hold moves inwards only when the robot
            # is found nearer than the hold itself (a localisation jump), never because it went
            # as near as the hold let it: min(held, inside) let it INSIDE_MARGIN_SLACK nearer
            # each cycle, and the matrix saw MPPI creep into a pillar of the TurtleBot3
            # sandbox at 2 mm/s, its estimate within 4 cm.
            # Never below the radius once the disc overlaps an obstacle: held at its depth,
            # a robot slid along a pillar of the TurtleBot3 sandbox and, pressed against it,
            # drove on at 0.45 m/s, as each laser hit drawn a centimetre nearer lowered the
            # hold again (to 0.06 m, with a 0.15 m radius). It may then only get out, or turn
            # on the spot (which gains nothing, and is allowed); in a gap narrower than its
            # disc no move gets out, and it stays until the estimate or the map changes.
            if held is None or clearance < held:
                self.held = max(inside, 0.0)
            else:
                self.held = held
            if clearance < radius:
                self.held = max(self.held, radius)
                self.escaping = True
                px, py = np.float32([pose[0]]), np.float32([pose[1]])
                self._start = (float(self.field.exact(px, py)[0]),
                               float(self.field.at(px, py)[0]))
            self.threshold = self.held
        else:
            self.threshold = limit

    def colliding(self, x: np.ndarray, y: np.ndarray,
                  costs: np.ndarray | None = None) -> np.ndarray:
        """Boolean array (the shape of ``x``): which poses collide. ``costs``: the cells'
        values at the poses when already looked up (:func:`rollout_costs`)."""
        hit = self._on_blocked_cells(x, y, costs)
        if self.escaping:
            hit |= self._not_getting_out(x, y, self.field.at(x, y), self._start[1])
        elif self.field is not None and self.threshold > 0.0:
            hit |= self.field.below(x, y, self.threshold)
        return hit

    def rollout_collides(self, x: np.ndarray, y: np.ndarray) -> bool:
        """Whether one rollout (1-D ``x``, ``y``) collides, with exact distances (the guard of
        the command: the critics' bilinear field may be off by up to half a cell diagonal)."""
        if self._on_blocked_cells(x, y).any():
            return True
        if self.escaping:
            clearance = self.field.exact(x, y)
            return bool(self._not_getting_out(x, y, clearance, self._start[0]).any())
        return bool(self.field is not None and self.threshold > 0.0
                    and (self.field.exact(x, y) < self.threshold).any())

    def _not_getting_out(self, x: np.ndarray, y: np.ndarray, clearance: np.ndarray,
                         start: float) -> np.ndarray:
        """Which poses of rollouts (the last axis: the steps, from the robot's pose) lie
        within the threshold with less than ``start`` (the robot's clearance) plus
        :data:`ESCAPE_GAIN` times the distance driven to them (less
        :data:`ESCAPE_TOLERANCE`), or nearer than ``start`` at all."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        dx = np.diff(x, axis=-1, prepend=np.full(x.shape[:-1] + (1,), self._pose[0]))
        dy = np.diff(y, axis=-1, prepend=np.full(y.shape[:-1] + (1,), self._pose[1]))
        driven = np.cumsum(np.hypot(dx, dy), axis=-1)
        needed = np.maximum(start + ESCAPE_GAIN * driven - ESCAPE_TOLERANCE,
                            start - ESCAPE_ROUNDING)
        return (clearance < self.threshold) & (clearance < needed)

    def _on_blocked_cells(self, x: np.ndarray, y: np.ndarray,
                          costs: np.ndarray | None = None) -> np.ndarray:
        """Which poses have their centre on an inscribed, lethal or (when it counts) unknown
        cell, or off the map."""
        if costs is None:
            costs = rollout_costs(self.costmap, x, y)
        hit = costs >= INSCRIBED_INFLATED_OBSTACLE
        if not self.unknown_is_obstacle:
            hit &= costs != NO_INFORMATION
        return hit
