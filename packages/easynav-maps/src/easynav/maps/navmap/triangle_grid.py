"""TriangleGrid: a uniform xy grid of triangle bounding boxes for point location on a NavMap."""

from __future__ import annotations

import numpy as np

#: Barycentric tolerance of the in-triangle test (the original's ``LocateOpts::planar_eps``).
PLANAR_EPS = 1e-4

#: Query points handled per vectorised batch (bounds the memory of the candidate pairs).
BATCH = 131072


class TriangleGrid:
    """Spatial index of a triangle surface for "which triangle lies under (x, y)".

    Every triangle is registered in the cells of a uniform xy grid that its xy bounding box
    overlaps (CSR layout: ``cell_start``/``cell_tris``). A query point takes the triangles of
    its cell as candidates; an exact barycentric test in xy keeps those whose projection
    contains the point (tolerance :data:`PLANAR_EPS`), and the surface height there is
    interpolated. Triangles whose xy projection is degenerate (vertical walls) are never
    candidates: a vertical ray does not locate on them.

    The cell side defaults to the mean larger bounding-box side of the triangles, grown when
    needed so that the grid has at most ``4 · M + 1024`` cells.

    Everything is vectorised numpy (no Python loop per point or per triangle).

    Thread contract: immutable after construction; queries may run from any thread.
    Exceptions: ``ValueError`` for malformed arrays.
    """

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, cell_size: float | None = None):
        vertices = np.asarray(vertices, dtype=np.float64)
        faces = np.asarray(faces, dtype=np.int64)
        tri = vertices[faces]  # (M, 3, 3)
        a = tri[:, 0, :2]
        e1 = tri[:, 1, :2] - a
        e2 = tri[:, 2, :2] - a
        det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        lo = tri[:, :, :2].min(axis=1)
        hi = tri[:, :, :2].max(axis=1)
        scale = np.maximum(np.abs(e1).max(axis=1), np.abs(e2).max(axis=1))
        valid = np.abs(det) > 1e-12 * np.maximum(scale * scale, 1e-300)
        self.a = a
        self.e1 = e1
        self.e2 = e2
        self.inv_det = np.where(valid, 1.0 / np.where(valid, det, 1.0), 0.0)
        self.z = np.ascontiguousarray(tri[:, :, 2])
        self.num_triangles = len(faces)
        ids = np.flatnonzero(valid)
        if len(ids) == 0:
            self.origin = np.zeros(2)
            self.cell = 1.0
            self.nx = self.ny = 1
            self.cell_start = np.zeros(2, dtype=np.int64)
            self.cell_tris = np.zeros(0, dtype=np.int64)
            return
        lo_v, hi_v = lo[ids], hi[ids]
        extent_lo, extent_hi = lo_v.min(axis=0), hi_v.max(axis=0)
        span = np.maximum(extent_hi - extent_lo, 1e-9)
        if cell_size is None or cell_size <= 0:
            cell_size = float(np.mean((hi_v - lo_v).max(axis=1)))
        cell_size = max(float(cell_size), 1e-9)
        max_cells = 4 * len(ids) + 1024
        while np.prod(np.floor(span / cell_size) + 1) > max_cells:
            cell_size *= 1.5
        self.origin = extent_lo
        self.cell = cell_size
        self.nx = int(np.floor(span[0] / cell_size)) + 1
        self.ny = int(np.floor(span[1] / cell_size)) + 1
        ix0, iy0 = self._cells(lo_v)
        ix1, iy1 = self._cells(hi_v)
        w = ix1 - ix0 + 1
        counts = w * (iy1 - iy0 + 1)
        rep = np.repeat(np.arange(len(ids)), counts)
        local = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        cells = (iy0[rep] + local // w[rep]) * self.nx + ix0[rep] + local % w[rep]
        order = np.argsort(cells, kind="stable")
        self.cell_tris = ids[rep[order]]
        self.cell_start = np.zeros(self.nx * self.ny + 1, dtype=np.int64)
        np.cumsum(np.bincount(cells, minlength=self.nx * self.ny), out=self.cell_start[1:])

    def _cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ij = np.floor((xy - self.origin) / self.cell).astype(np.int64)
        return np.clip(ij[:, 0], 0, self.nx - 1), np.clip(ij[:, 1], 0, self.ny - 1)

    def candidates(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(point_index, triangle)`` pairs: the triangles registered in each point's cell."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        rel = (xy - self.origin) / self.cell
        inside = (
            np.isfinite(rel).all(axis=1)
            & (rel[:, 0] >= 0) & (rel[:, 0] < self.nx)
            & (rel[:, 1] >= 0) & (rel[:, 1] < self.ny)
        )
        ids = np.flatnonzero(inside)
        ij = np.floor(rel[ids]).astype(np.int64)
        cell = ij[:, 1] * self.nx + ij[:, 0]
        start = self.cell_start[cell]
        counts = self.cell_start[cell + 1] - start
        pidx = np.repeat(ids, counts)
        offset = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        return pidx, self.cell_tris[np.repeat(start, counts) + offset]

    def evaluate(
        self, xy: np.ndarray, pidx: np.ndarray, tidx: np.ndarray, planar_eps: float = PLANAR_EPS
    ) -> tuple[np.ndarray, np.ndarray]:
        """For pairs ``(pidx, tidx)``: a mask of those whose triangle contains the point in xy
        and the surface height there (meaningful where the mask holds)."""
        d = xy[pidx] - self.a[tidx]
        e1, e2, inv = self.e1[tidx], self.e2[tidx], self.inv_det[tidx]
        l1 = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) * inv
        l2 = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) * inv
        l0 = 1.0 - l1 - l2
        ok = (inv != 0.0) & (l0 >= -planar_eps) & (l1 >= -planar_eps) & (l2 >= -planar_eps)
        z = self.z[tidx]
        return ok, l0 * z[:, 0] + l1 * z[:, 1] + l2 * z[:, 2]

    def locate(
        self,
        points: np.ndarray,
        height_eps: float | None = None,
        downward: bool = False,
        planar_eps: float = PLANAR_EPS,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Triangle under each of ``points`` (K, 3): ``(cids (K,) int64, -1 if none; surface
        heights (K,) float64, NaN if none)``. See :meth:`NavMap.locate` for the choice rule."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        cids = np.full(len(points), -1, dtype=np.int64)
        heights = np.full(len(points), np.nan)
        for s in range(0, len(points), BATCH):
            chunk = points[s : s + BATCH]
            xy = chunk[:, :2]
            pidx, tidx = self.candidates(xy)
            c, h = select(chunk, pidx, tidx, *self.evaluate(xy, pidx, tidx, planar_eps),
                          height_eps, downward)
            cids[s : s + BATCH] = c
            heights[s : s + BATCH] = h
        return cids, heights


def select(
    points: np.ndarray,
    pidx: np.ndarray,
    tidx: np.ndarray,
    ok: np.ndarray,
    z_surface: np.ndarray,
    height_eps: float | None,
    downward: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Pick one triangle per point among the containing candidates (see NavMap.locate)."""
    cids = np.full(len(points), -1, dtype=np.int64)
    heights = np.full(len(points), np.nan)
    dz = points[pidx, 2] - z_surface
    if downward:
        eps = 0.0 if height_eps is None else float(height_eps)
        ok = ok & (dz >= -eps)
        score = dz  # the highest surface at or below z + eps: the first hit of the ray
    else:
        score = np.abs(dz)
        if height_eps is not None:
            ok = ok & (score <= height_eps)
    keep = np.flatnonzero(ok)
    if len(keep) == 0:
        return cids, heights
    p, t, sc = pidx[keep], tidx[keep], score[keep]
    order = np.lexsort((t, sc, p))
    p, t = p[order], t[order]
    first = np.ones(len(p), dtype=bool)
    first[1:] = p[1:] != p[:-1]
    cids[p[first]] = t[first]
    heights[p[first]] = z_surface[keep][order][first]
    return cids, heights


def locate_reference(
    grid: TriangleGrid,
    points: np.ndarray,
    height_eps: float | None = None,
    downward: bool = False,
    planar_eps: float = PLANAR_EPS,
) -> tuple[np.ndarray, np.ndarray]:
    """Brute-force :meth:`TriangleGrid.locate`: every point against every triangle (no index).

    The readable reference for tests and the benchmark: O(K · M) work, one point at a time.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    cids = np.full(len(points), -1, dtype=np.int64)
    heights = np.full(len(points), np.nan)
    all_tris = np.arange(grid.num_triangles)
    for k, point in enumerate(points):
        one = point[None, :]
        pidx = np.zeros(len(all_tris), dtype=np.int64)
        ok, z = grid.evaluate(one[:, :2], pidx, all_tris, planar_eps)
        c, h = select(one, pidx, all_tris, ok, z, height_eps, downward)
        cids[k], heights[k] = c[0], h[0]
    return cids, heights
