"""Path geometry for Regulated Pure Pursuit: cusps, projection on a path, the carrot.

Plain numpy functions on ``(N, 2)`` arrays of path positions, without ROS; the RT thread of the
controller calls them every cycle. All are pure (no state, any thread).
"""

from __future__ import annotations

import math

import numpy as np


def cusp_indices(path_xy: np.ndarray) -> np.ndarray:
    """Indices of the vertices where the path reverses its direction of travel (cusps).

    Vertex ``i`` (0 < i < N-1) is a cusp when the segments before and after it point in opposite
    directions (negative dot product): a Reeds–Shepp path switching between forward and reverse.
    Zero-length segments are ignored (they have no direction).
    """
    if len(path_xy) < 3:
        return np.zeros(0, dtype=np.int64)
    seg = np.diff(path_xy, axis=0)
    nonzero = np.flatnonzero(np.einsum("ij,ij->i", seg, seg) > 1e-18)
    if len(nonzero) < 2:
        return np.zeros(0, dtype=np.int64)
    a, b = seg[nonzero[:-1]], seg[nonzero[1:]]
    flips = np.einsum("ij,ij->i", a, b) < 0.0
    # The cusp is the vertex that ends the segment before the flip.
    return nonzero[1:][flips].astype(np.int64)


def project_on_path(
    path_xy: np.ndarray, position: np.ndarray, first: int, last: int
) -> tuple[int, float, np.ndarray]:
    """The point of the polyline ``path_xy[first..last]`` closest to ``position``.

    Returns ``(segment, t, point)``: the point is ``path_xy[segment] + t·(path_xy[segment+1] -
    path_xy[segment])`` with ``t`` in [0, 1]; a single vertex (``first == last``) gives
    ``(first, 0.0, path_xy[first])``.
    """
    if last <= first:
        return first, 0.0, path_xy[first].copy()
    a = path_xy[first:last]
    ab = path_xy[first + 1 : last + 1] - a
    length2 = np.einsum("ij,ij->i", ab, ab)
    t = np.einsum("ij,ij->i", position - a, ab) / np.where(length2 > 0.0, length2, 1.0)
    np.clip(t, 0.0, 1.0, out=t)
    points = a + t[:, None] * ab
    d = points - position
    best = int(np.argmin(np.einsum("ij,ij->i", d, d)))
    return first + best, float(t[best]), points[best]


def _circle_segment(p1: np.ndarray, p2: np.ndarray, center: np.ndarray, r: float) -> np.ndarray:
    """The intersection of segment p1→p2 with the circle (center, r), p1 inside, p2 outside.

    Solves |p1 + s(p2 - p1) - c| = r for the root s in [0, 1] (the larger one: p1 is inside).
    """
    d = p2 - p1
    f = p1 - center
    a = float(d @ d)
    if a <= 0.0:
        return p2.copy()
    b = 2.0 * float(f @ d)
    c = float(f @ f) - r * r
    disc = max(b * b - 4.0 * a * c, 0.0)
    s = (-b + math.sqrt(disc)) / (2.0 * a)
    return p1 + min(max(s, 0.0), 1.0) * d


def carrot_point(
    path_xy: np.ndarray,
    position: np.ndarray,
    start: int,
    end: int,
    distance: float,
    extend_after_end: bool = False,
    first_point: np.ndarray | None = None,
) -> np.ndarray:
    """The first point of ``path_xy[start..end]`` at ``distance`` from ``position``.

    ``first_point`` (the robot's projection on the path) is prepended when given. Searches
    forward from vertex ``start`` (the vertex after the robot's projection) for the first vertex
    at least
    ``distance`` away and interpolates the crossing of the circle of radius ``distance`` on the
    segment before it (Nav2's circle/segment intersection). None that far: the end vertex, or,
    with ``extend_after_end``, the point at ``distance`` on the line through the last segment
    extended past the end (``interpolate_curvature_after_goal``).
    """
    window = path_xy[start : end + 1]
    if first_point is not None:
        window = np.vstack((first_point[None, :], window))
    d = window - position
    far = np.flatnonzero(np.einsum("ij,ij->i", d, d) >= distance * distance)
    if len(far):
        i = int(far[0])
        if i == 0:
            return window[0].copy()
        return _circle_segment(window[i - 1], window[i], position, distance)
    last = window[-1]
    if not extend_after_end or end == 0:
        return last.copy()
    # Direction of the last non-degenerate segment.
    k = end
    while k > 0 and np.allclose(path_xy[k], path_xy[k - 1]):
        k -= 1
    if k == 0:
        return last.copy()
    direction = path_xy[k] - path_xy[k - 1]
    direction = direction / math.hypot(direction[0], direction[1])
    return _circle_segment(last, last + direction * (2.0 * distance + 1.0), position, distance)
