"""Moving a path away from obstacles where there is room: clearance-aware centring.

A sampling planner's simplified path is the shortest it found: it rounds every corner as close
as its collision test allows. A follower that cuts corners (a carrot ahead, a turn that takes
time) then clips them. :func:`center_path` pushes each pose of a path away from the nearest
obstacle until it has ``wanted`` metres of clearance (or as much as the place allows: the
middle of a passage narrower than twice that) while a smoothing term keeps the path from
kinking; the ends stay where they are.

The push follows the gradient of a clearance field (metres to the nearest obstacle, per cell),
so it moves poses away from obstacles, not across them; the smoothing and the final resampling
are not bounded by the field, so the caller checks the result (and keeps its own path if the
moved one fails). Only the part of the push normal to the path is applied, so poses do not
bunch along it; the path is resampled at the end. It is plain numpy (a few hundred poses,
tens of vectorised iterations: about a millisecond).
"""

from __future__ import annotations

import math

import numpy as np

#: Iterations: enough for a pose to travel ``wanted`` at half a cell per iteration, capped.
MAX_ITERATIONS = 200
#: Weight of the smoothing (the pull of each pose towards the midpoint of its neighbours).
SMOOTHING = 0.3


def resample(xy: np.ndarray, step: float) -> np.ndarray:
    """``xy`` (``(K, 2)``) resampled at even arc lengths no longer than ``step`` (ends kept)."""
    if len(xy) < 2:
        return xy
    seg = np.hypot(*np.diff(xy, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    total = s[-1]
    if total <= 0.0:
        return xy[[0, -1]]
    n = max(1, math.ceil(total / step - 1e-9))
    t = np.linspace(0.0, total, n + 1)
    out = np.column_stack([np.interp(t, s, xy[:, 0]), np.interp(t, s, xy[:, 1])])
    out[0], out[-1] = xy[0], xy[-1]
    return out


class ClearanceGradient:
    """Bilinear clearance (m) and its gradient over a grid of cell values.

    ``clearance[iy, ix]`` is the clearance at the centre of cell ``(ix, iy)`` of a grid whose
    lower-left corner is ``(origin_x, origin_y)`` and cells ``resolution`` metres wide, at least
    2 x 2 cells (:class:`ValueError` otherwise: there is no gradient).
    """

    def __init__(
        self, clearance: np.ndarray, origin_x: float, origin_y: float, resolution: float
    ) -> None:
        self.values = np.asarray(clearance, dtype=np.float64)
        if self.values.ndim != 2 or min(self.values.shape) < 2:
            raise ValueError(f"a clearance grid of shape {self.values.shape} has no gradient")
        self.origin = (float(origin_x), float(origin_y))
        self.resolution = float(resolution)
        gy, gx = np.gradient(self.values, self.resolution)
        self._gx, self._gy = gx, gy

    def _corners(self, xy: np.ndarray):
        h, w = self.values.shape
        fx = (xy[:, 0] - self.origin[0]) / self.resolution - 0.5
        fy = (xy[:, 1] - self.origin[1]) / self.resolution - 0.5
        fx = np.clip(fx, 0.0, w - 1.000001)
        fy = np.clip(fy, 0.0, h - 1.000001)
        ix, iy = np.floor(fx).astype(np.intp), np.floor(fy).astype(np.intp)
        return ix, iy, fx - ix, fy - iy

    def _sample(self, grid: np.ndarray, corners) -> np.ndarray:
        ix, iy, tx, ty = corners
        ix1 = np.minimum(ix + 1, grid.shape[1] - 1)
        iy1 = np.minimum(iy + 1, grid.shape[0] - 1)
        bottom = grid[iy, ix] * (1 - tx) + grid[iy, ix1] * tx
        top = grid[iy1, ix] * (1 - tx) + grid[iy1, ix1] * tx
        return bottom * (1 - ty) + top * ty

    def at(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Clearance (``(K,)``) and gradient (``(K, 2)``) at the points ``xy`` (``(K, 2)``)."""
        corners = self._corners(xy)
        value = self._sample(self.values, corners)
        grad = np.column_stack([self._sample(self._gx, corners), self._sample(self._gy, corners)])
        return value, grad


def center_path(
    xy: np.ndarray,
    field: ClearanceGradient,
    wanted: float,
    step: float,
    smoothing: float = SMOOTHING,
) -> np.ndarray:
    """``xy`` (``(K, 2)``, ends kept) moved to ``wanted`` metres of clearance where the field
    allows, smoothed, and resampled every ``step`` metres.

    Each iteration moves every inner pose, at once, by the part normal to the path of
    ``min(wanted - clearance, half a cell)`` along the clearance gradient (nothing where the
    clearance is already ``wanted``), plus ``smoothing`` times its offset from the midpoint of
    its neighbours. Where the room is narrower than ``2 * wanted`` the pose settles in the middle
    (the gradient fades to nothing there). The caller checks the result against its
    collision rule: the push raises the clearance of every pose, but the smoothing may lower it
    where the path bends round a corner narrower than ``wanted``.
    """
    xy = resample(np.asarray(xy, dtype=np.float64), step)
    if len(xy) < 3 or wanted <= 0.0:
        return xy
    cell = field.resolution
    max_push = 0.5 * cell
    iterations = min(MAX_ITERATIONS, 2 * math.ceil(wanted / max_push) + 10)
    points = xy.copy()
    for _ in range(iterations):
        inner = points[1:-1]
        clearance, grad = field.at(inner)
        # The gradient, not its direction: it fades to nothing across the ridge of the field
        # (the middle of a passage), where a unit push would flip the pose from side to side.
        norm = np.hypot(grad[:, 0], grad[:, 1])
        grad /= np.maximum(norm, 1.0)[:, None]
        push = grad * np.clip(wanted - clearance, 0.0, max_push)[:, None]
        tangent = points[2:] - points[:-2]
        tangent /= np.maximum(np.hypot(tangent[:, 0], tangent[:, 1]), 1e-12)[:, None]
        push -= np.sum(push * tangent, axis=1)[:, None] * tangent
        midpoint = 0.5 * (points[:-2] + points[2:])
        moved = inner + push + smoothing * (midpoint - inner)
        settled = np.max(np.abs(moved - inner)) < 1e-4
        points[1:-1] = moved
        if settled:
            break
    return resample(points, step)
