"""Scoring 3D scans against a Bonxai voxel map for the NavMap AMCL (as the original EasyNav's
easynav_navmap_localizer does: particles predicted on the NavMap, corrected on ``map.bonxai``).

- :class:`InflatedVoxelMap`: the inflated likelihood map the original builds on first use and
  keeps under ``map.bonxai.inflated``: every voxel within reach of an occupied voxel of the
  source :class:`BonxaiMap` holds ``exp(-d² / 2σ²)`` (``d`` the Euclidean distance between voxel
  centres, kept where it is at least ``p_min``), occupied voxels 1. Stored densely over the
  occupied voxels' bounding box (plus the inflation radius) as one uint8 code per voxel: 255 =
  occupied in the source map, else ``round(254 p)``; one array answers both questions of the
  scoring (the probability at a point's end voxel, and whether a ray crosses an occupied voxel).
- :func:`score_particles`: for every particle × point, the inflated probability at the point's
  end voxel, zeroed when the probability is at least :data:`RAY_CHECK_MIN_PROBABILITY` and the
  ray from the sensor's voxel to the end voxel crosses an occupied voxel before the last
  ``tail_skip`` voxels (the original's rule). The ray walk is the original's integer 3D DDA in
  closed form (:func:`rays_occluded`). Compiled with numba when installed (one loop, each ray
  walked until its first occupied voxel); else vectorised with numpy over particles × points
  and over rays and steps, the compiled loop's reference.
- :func:`ray_occluded_reference` and :func:`score_reference`: the original's loops, one ray and
  one particle at a time, the readable references of the tests.

Differences from the original, on purpose: Euclidean distances (the original's brushfire
counts 6-connected steps, so diagonal neighbours get a lower probability than their distance
says) and probabilities not clamped to the Bonxai map's ``[clamp_min, clamp_max]`` (there a
voxel at ``p_min`` scores 0.12). The map is a snapshot: a source map changed in place later
(live mapping) is not followed until the NavState key is erased or the map object replaced.

Pure functions on numpy arrays, any thread; :class:`InflatedVoxelMap` is immutable.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.common.compiled_kernels import CompiledKernel
from easynav.maps.voxel.bonxai_map import BonxaiMap
from easynav.maps.voxel.voxel_rays import unpack_keys

#: Code of a voxel occupied in the source map.
OCCUPIED = 255
#: Rays are checked for occlusion only to points whose probability is at least this (original).
RAY_CHECK_MIN_PROBABILITY = 0.4
#: The dense box may hold at most this many voxels (256 MB of codes).
MAX_VOXELS = 1 << 28
#: Ray cells looked up per vectorised batch (bounds the memory of the batch).
RAY_BATCH = 1 << 22


def inflation_radius(sigma: float, p_min: float) -> float:
    """Distance (m) at which ``exp(-d²/2σ²)`` falls to ``p_min``."""
    p_min = min(max(p_min, 1e-6), 0.999999)
    return sigma * math.sqrt(-2.0 * math.log(p_min))


def tail_skip(resolution: float, sigma: float, p_min: float) -> int:
    """Voxels before a ray's end not checked for occlusion (the original's
    ``compute_tail_skip``): the wall a point lies on, and its inflation, do not hide it."""
    return max(1, math.ceil(inflation_radius(sigma, p_min) / resolution))


class InflatedVoxelMap:
    """The inflated likelihood map of a :class:`BonxaiMap` (see the module docstring).

    Attributes: ``source`` (the map it was built from), ``resolution``, ``sigma``, ``p_min``,
    ``origin`` (int64 ``(3,)`` voxel index of the box's first voxel), ``codes`` (uint8
    ``(nx, ny, nz)``), ``tail_skip``. Raises ``ValueError`` when the box would exceed
    :data:`MAX_VOXELS` or for a non-positive ``sigma``.
    """

    def __init__(self, source: BonxaiMap, sigma: float, p_min: float) -> None:
        if not (math.isfinite(sigma) and sigma > 0.0):
            raise ValueError(f"inflation sigma must be finite and > 0, got {sigma}")
        self.source = source
        self.resolution = float(source.resolution)
        self.sigma = float(sigma)
        self.p_min = float(p_min)
        self.tail_skip = tail_skip(self.resolution, self.sigma, self.p_min)
        ix, iy, iz = unpack_keys(source.occupied_keys())
        occupied = np.stack((ix, iy, iz), axis=1)
        reach = int(math.floor(inflation_radius(self.sigma, self.p_min) / self.resolution))
        if len(occupied) == 0:
            self.origin = np.zeros(3, dtype=np.int64)
            self.codes = np.zeros((1, 1, 1), dtype=np.uint8)
            return
        lo = occupied.min(axis=0) - reach
        shape = occupied.max(axis=0) + reach - lo + 1
        if int(np.prod(shape)) > MAX_VOXELS:
            raise ValueError(
                f"inflated map box {tuple(int(s) for s in shape)} voxels exceeds {MAX_VOXELS}"
            )
        self.origin = lo.astype(np.int64)
        codes = np.zeros(int(np.prod(shape)), dtype=np.uint8)
        strides = np.array((shape[1] * shape[2], shape[2], 1), dtype=np.int64)
        seeds = (occupied - lo) @ strides
        # Offsets within the radius, grouped by squared distance, weakest first.
        r = np.arange(-reach, reach + 1)
        off = np.stack(np.meshgrid(r, r, r, indexing="ij"), axis=-1).reshape(-1, 3)
        d2 = (off * off).sum(axis=1)
        probability = np.exp(-d2 * self.resolution**2 / (2.0 * self.sigma**2))
        keep = (d2 > 0) & (probability >= self.p_min)
        off, d2, probability = off[keep], d2[keep], probability[keep]
        chunk = max(1, (1 << 22) // max(1, len(off)))
        for value in np.unique(d2)[::-1]:
            group = off[d2 == value] @ strides
            code = np.uint8(min(254, round(254.0 * float(probability[d2 == value][0]))))
            if code == 0:
                continue
            for a in range(0, len(seeds), chunk):
                flat = (seeds[a : a + chunk, None] + group[None, :]).ravel()
                codes[flat] = np.maximum(codes[flat], code)
        codes[seeds] = OCCUPIED
        self.codes = codes.reshape(tuple(int(s) for s in shape))

    def codes_at(self, cells: np.ndarray) -> np.ndarray:
        """The codes of integer voxel indices ``cells`` (..., 3); 0 outside the box."""
        rel = np.asarray(cells, dtype=np.int64) - self.origin
        nx, ny, nz = self.codes.shape
        inside = (
            (rel[..., 0].view(np.uint64) < nx)
            & (rel[..., 1].view(np.uint64) < ny)
            & (rel[..., 2].view(np.uint64) < nz)
        )
        flat = np.clip((rel[..., 0] * ny + rel[..., 1]) * nz + rel[..., 2], 0,
                       self.codes.size - 1)
        return np.where(inside, self.codes.reshape(-1)[flat], np.uint8(0))

    def probability_at(self, points: np.ndarray) -> np.ndarray:
        """Inflated probability at ``points`` (..., 3) in metres (0 outside the box)."""
        codes = self.codes_at(self.cells_of(points))
        return np.where(codes == OCCUPIED, 1.0, codes / 254.0)

    def cells_of(self, points: np.ndarray) -> np.ndarray:
        """Integer voxel indices of ``points`` (..., 3) in metres."""
        return np.floor(np.asarray(points, dtype=np.float64) / self.resolution).astype(np.int64)

    def is_occupied_cell(self, cells: np.ndarray) -> np.ndarray:
        """Whether voxels ``cells`` (..., 3) are occupied in the source map (at build time)."""
        return self.codes_at(cells) == OCCUPIED


def rays_occluded(inflated: InflatedVoxelMap, a: np.ndarray, b: np.ndarray,
                  skip: int | None = None) -> np.ndarray:
    """For rays from voxel ``a`` to voxel ``b`` (both ``(K, 3)`` int64): whether an occupied
    voxel lies on the ray before its last ``skip`` (default ``inflated.tail_skip``) voxels.

    The original's DDA steps ``n = max |b - a|`` times along the major axis; after ``k`` steps
    each axis has moved ``floor((n // 2 + k·|Δ|) / n)`` voxels (its error accumulator starts at
    ``n // 2`` and wraps every ``n``), and cells ``k < n - skip - 1`` are checked. That closed
    form is evaluated for all rays and steps at once, in batches of :data:`RAY_BATCH` cells.
    """
    skip = inflated.tail_skip if skip is None else skip
    a = np.asarray(a, dtype=np.int64).reshape(-1, 3)
    b = np.asarray(b, dtype=np.int64).reshape(-1, 3)
    delta = b - a
    steps = np.abs(delta)
    sign = np.where(delta >= 0, 1, -1)
    n = steps.max(axis=1)
    checks = np.maximum(n - max(0, skip) - 1, 0)
    occluded = np.zeros(len(a), dtype=bool)
    rays = np.flatnonzero(checks)
    start = 0
    while start < len(rays):
        # As many rays as fit in one batch of cells (at least one).
        total = np.cumsum(checks[rays[start:]])
        stop = start + max(1, int(np.searchsorted(total, RAY_BATCH, side="right")))
        batch = rays[start:stop]
        counts = checks[batch]
        ray = np.repeat(batch, counts)
        k = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        nn = n[ray][:, None]
        cells = a[ray] + sign[ray] * ((nn // 2 + k[:, None] * steps[ray]) // nn)
        hit = inflated.is_occupied_cell(cells)
        occluded[ray[hit]] = True
        start = stop
    return occluded


def ray_occluded_reference(inflated: InflatedVoxelMap, a, b, skip: int | None = None) -> bool:
    """The original's ``ray_occluded_dda`` for one ray, step by step (the tests' reference)."""
    skip = inflated.tail_skip if skip is None else skip
    x, y, z = (int(v) for v in a)
    xe, ye, ze = (int(v) for v in b)
    dx, dy, dz = abs(xe - x), abs(ye - y), abs(ze - z)
    sx, sy, sz = (1 if xe >= x else -1), (1 if ye >= y else -1), (1 if ze >= z else -1)
    nsteps = max(dx, dy, dz)
    if nsteps <= 0:
        return False
    ex = ey = ez = nsteps // 2
    for step in range(nsteps):
        if step < nsteps - max(0, skip) - 1 and inflated.is_occupied_cell(
            np.array([x, y, z])
        ):
            return True
        if dx >= dy and dx >= dz:
            x += sx
            ey += dy
            ez += dz
            if ey >= dx:
                y += sy
                ey -= dx
            if ez >= dx:
                z += sz
                ez -= dx
        elif dy >= dx and dy >= dz:
            y += sy
            ex += dx
            ez += dz
            if ex >= dy:
                x += sx
                ex -= dy
            if ez >= dy:
                z += sz
                ez -= dy
        else:
            z += sz
            ex += dx
            ey += dy
            if ex >= dz:
                x += sx
                ex -= dz
            if ey >= dz:
                y += sy
                ey -= dz
    return False


def point_scores(inflated: InflatedVoxelMap, origins: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Score of each ray (``origins``, ``ends`` in metres, same shape (..., 3)): the inflated
    probability at the end voxel, zeroed when it is at least :data:`RAY_CHECK_MIN_PROBABILITY`
    and the ray is occluded (:func:`rays_occluded`)."""
    shape = ends.shape[:-1]
    end_cells = inflated.cells_of(ends).reshape(-1, 3)
    codes = inflated.codes_at(end_cells)
    scores = np.where(codes == OCCUPIED, 1.0, codes / 254.0)
    check = np.flatnonzero(scores >= RAY_CHECK_MIN_PROBABILITY)
    if len(check):
        start = inflated.cells_of(np.broadcast_to(origins, ends.shape).reshape(-1, 3)[check])
        scores[check[rays_occluded(inflated, start, end_cells[check])]] = 0.0
    return scores.reshape(shape)


def score_particles(
    inflated: InflatedVoxelMap,
    rotations: np.ndarray,
    translations: np.ndarray,
    points: np.ndarray,
    origins: np.ndarray,
    chunk: int = 32,
    compiled: bool = True,
) -> np.ndarray:
    """Sum of the point scores (:func:`point_scores`) of each particle: ``rotations`` ``(N, 3,
    3)`` and ``translations`` ``(N, 3)`` place the robot footprint frame in the map; ``points``
    ``(M, 3)`` are in the footprint frame, ``origins`` ``(M, 3)`` the position of the sensor
    that measured each point (footprint frame).

    With numba installed (and ``compiled``) one compiled loop (``_voxel_scoring_numba``) whose
    ray walks stop at the first occupied voxel; otherwise vectorised over ``chunk`` particles ×
    all points at a time, every voxel of every checked ray looked up (this numpy version is the
    compiled one's reference, ``compiled=False``)."""
    n = len(rotations)
    sums = np.zeros(n)
    if n == 0 or len(points) == 0:
        return sums
    kernel = COMPILED_SCORING.get() if compiled else None
    if kernel is not None:
        # The compiled loop indexes without bounds checks: shapes are checked here, and
        # origins broadcast as the numpy version broadcasts them.
        points = np.asarray(points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3:
            raise ValueError(f"points must be (M, 3), got {points.shape}")
        if np.shape(rotations) != (n, 3, 3) or np.shape(translations) != (n, 3):
            raise ValueError(f"rotations {np.shape(rotations)} and translations "
                             f"{np.shape(translations)} must be ({n}, 3, 3) and ({n}, 3)")
        return kernel(
            np.ascontiguousarray(rotations, dtype=np.float64),
            np.ascontiguousarray(translations, dtype=np.float64),
            np.ascontiguousarray(points),
            np.ascontiguousarray(np.broadcast_to(origins, points.shape), dtype=np.float64),
            inflated.codes,
            inflated.origin,
            inflated.resolution,
            int(inflated.tail_skip),
            OCCUPIED,
            RAY_CHECK_MIN_PROBABILITY,
        )
    for a in range(0, n, chunk):
        rot, trans = rotations[a : a + chunk], translations[a : a + chunk]
        ends = np.einsum("nij,mj->nmi", rot, points) + trans[:, None, :]
        starts = np.einsum("nij,mj->nmi", rot, origins) + trans[:, None, :]
        sums[a : a + chunk] = point_scores(inflated, starts, ends).sum(axis=1)
    return sums


#: The compiled scoring (:func:`score_particles`), None from ``get()`` without numba.
COMPILED_SCORING = CompiledKernel("easynav.localizers._voxel_scoring_numba", "score_kernel")


def score_reference(inflated: InflatedVoxelMap, rotations, translations, points,
                    origins) -> np.ndarray:
    """:func:`score_particles` one particle and one point at a time with
    :func:`ray_occluded_reference` (the original's loop; the tests' reference)."""
    sums = np.zeros(len(rotations))
    for i, (rot, trans) in enumerate(zip(rotations, translations, strict=True)):
        total = 0.0
        for point, origin in zip(points, origins, strict=True):
            end = rot @ point + trans
            start = rot @ origin + trans
            p = float(inflated.probability_at(end[None, :])[0])
            if p >= RAY_CHECK_MIN_PROBABILITY and ray_occluded_reference(
                inflated, inflated.cells_of(start), inflated.cells_of(end)
            ):
                p = 0.0
            total += p
        sums[i] = total
    return sums
