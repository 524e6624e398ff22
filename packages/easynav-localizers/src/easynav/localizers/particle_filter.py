"""ParticleFilter2D: the vectorised particle filter behind the simple AMCL localizer."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.compiled_kernels import CompiledKernel

#: Cost of a lethal cell in a Costmap2D: the cells a laser point hits (the original's 254).
LETHAL = 254

#: From this many particle × point pairs on, the compiled scoring pays for loading numba in a
#: process that would load it for the scoring alone (the simple stack's): measured (issue
#: #21), 200 particles × 360 points take 0.4-0.5 ms in numpy against 0.1 ms compiled, under
#: 0.3 % of a core at a 5 Hz correction, while numba and LLVM take about 100 MB resident.
#: See :func:`compiled_scoring_pays`.
COMPILED_SCORING_MIN_PAIRS = 100_000


def occupied_cells(grid) -> np.ndarray:
    """The obstacle cells of a map as a ``(height, width)`` bool array: a :class:`SimpleMap`'s
    occupied cells, or a Costmap2D's lethal (254) cells (unknown 255 and the inflated 253 are
    not obstacles a laser can hit)."""
    cells = getattr(grid, "cells", None)
    if cells is not None:
        return np.asarray(cells, dtype=bool)
    return np.asarray(grid.data) == LETHAL


#: How deep into an obstacle a range sensor's points may land (m): the skin of
#: :func:`surface_cells`. A wall up to twice this thick keeps every cell.
SURFACE_DEPTH = 0.3


def surface_cells(grid, depth: float = SURFACE_DEPTH) -> np.ndarray:
    """The obstacle cells a range sensor can hit: the :func:`occupied_cells` within ``depth``
    metres (at least one cell) of a cell that is not occupied or of the map's edge, counted in
    4-neighbour steps: exact along the grid's axes, about 0.7 of it across a diagonal wall.
    ``(height, width)`` bool. Raises ValueError for a negative or non-finite ``depth``.

    Why not every occupied cell: a laser point lands on an obstacle's face, never inside it.
    A map that draws a building or a pillar as a filled block (drawn and CAD maps do; a SLAM
    map leaves the inside unknown) would otherwise score a scan that lands inside the block
    as a perfect fit, so a pose too close to the block beats the true one and the filter
    cannot correct it. Measured on the playground's campus (buildings 10-20 m across): 2 m
    from a building's wall, the true pose's scan fitted worse than the pose 1.6 m closer,
    whose points fell inside the building (likelihood field 8.4 against 13.6; exact hits 41
    against 76 of 76 points), and AMCL kept a 1.9 m error. Walls of ordinary thickness are
    unchanged (along the grid up to twice ``depth``).
    """
    if not (math.isfinite(depth) and depth >= 0.0):
        raise ValueError(f"surface depth = {depth} must be finite and >= 0")
    cells = occupied_cells(grid)
    steps = max(1, int(math.ceil(depth / float(grid.resolution) - 1e-9)))
    inside = cells
    for _ in range(steps):
        if not inside.any():
            break
        around = np.pad(inside, 1, constant_values=False)
        inside = (inside & around[:-2, 1:-1] & around[2:, 1:-1]
                  & around[1:-1, :-2] & around[1:-1, 2:])
    return cells & ~inside


def _wrap(angles: np.ndarray) -> np.ndarray:
    return (angles + np.pi) % (2.0 * np.pi) - np.pi


def likelihood_field(grid, sigma: float) -> np.ndarray:
    """How much a point in each cell of ``grid`` (a :class:`SimpleMap` or a Costmap2D, see
    :func:`occupied_cells`) counts as a hit: ``exp(-d² / 2σ²)`` for a cell whose centre
    is ``d`` metres from the nearest obstacle surface cell centre (:func:`surface_cells`: 1 on
    them, and low deep inside a filled obstacle); ``sigma`` 0 gives exact hits (1 on surface
    cells, 0 elsewhere). ``(height, width)`` float32.

    The soft version widens the basin around the true pose: a particle 0.3 m off still scores
    better than one 1 m off, so the cloud is pulled towards the truth instead of waiting for
    random samples to land on it.
    """
    if not math.isfinite(sigma) or sigma < 0.0:
        raise ValueError(f"hit sigma = {sigma} must be finite and >= 0")
    cells = surface_cells(grid)
    if sigma == 0.0 or not cells.any():
        return cells.astype(np.float32)
    import cv2  # here: a process that never needs a soft field does not load OpenCV

    free = (~cells).astype(np.uint8)
    distance = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * grid.resolution
    return np.exp(-0.5 * np.square(distance / sigma)).astype(np.float32)


def hit_fractions(
    poses: np.ndarray,
    points_xy: np.ndarray,
    grid,
    field: np.ndarray | None = None,
    chunk: int = 128,
    compiled: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """For each particle pose ``(x, y, yaw)``: the fraction of ``points_xy`` (robot frame) that
    hit obstacle surface cells of ``grid`` (a :class:`SimpleMap` or a Costmap2D, see
    :func:`surface_cells`), and how many landed on the map at all.

    ``field`` (from :func:`likelihood_field`) says how much a point in each cell counts as a
    hit; None counts exact hits on surface cells (the original's score, which counts every
    occupied cell: the same on walls of ordinary thickness). A particle whose
    points all fall off the map scores 0. Vectorised over particles × points, in float32 cell
    units and ``chunk`` particles at a time, which keeps the intermediate arrays in cache (4–5×
    faster than one float64 pass for 1000 particles). With numba installed (and ``compiled``)
    the same scoring runs as one compiled loop (``_scoring_numba``), several times faster again;
    this numpy version is its reference (``compiled=False``, see
    :func:`compiled_scoring_pays`).
    """
    n = len(poses)
    fractions = np.zeros(n)
    possible = np.zeros(n, dtype=np.int64)
    if n == 0 or len(points_xy) == 0 or grid.width == 0 or grid.height == 0:
        return fractions, possible
    if field is None:
        field = surface_cells(grid).astype(np.float32)
    elif field.shape != (grid.height, grid.width):
        raise ValueError(
            f"likelihood field shape {field.shape} != map shape {(grid.height, grid.width)}"
        )
    kernel = COMPILED_SCORING.get() if compiled else None
    if kernel is not None:
        return kernel(
            np.ascontiguousarray(poses, dtype=np.float64),
            np.ascontiguousarray(points_xy[:, :2], dtype=np.float64),
            np.ascontiguousarray(field, dtype=np.float32).ravel(),
            grid.width,
            grid.height,
            float(grid.origin_x),
            float(grid.origin_y),
            float(grid.resolution),
        )
    inv = 1.0 / grid.resolution
    px = (points_xy[:, 0] * inv).astype(np.float32)[None, :]
    py = (points_xy[:, 1] * inv).astype(np.float32)[None, :]
    ox = ((poses[:, 0] - grid.origin_x) * inv).astype(np.float32)[:, None]
    oy = ((poses[:, 1] - grid.origin_y) * inv).astype(np.float32)[:, None]
    c = np.cos(poses[:, 2]).astype(np.float32)[:, None]
    s = np.sin(poses[:, 2]).astype(np.float32)[:, None]
    values = np.ascontiguousarray(field, dtype=np.float32).ravel()
    width, height = grid.width, grid.height
    for a in range(0, n, chunk):
        b = min(n, a + chunk)
        gx = np.floor(ox[a:b] + c[a:b] * px - s[a:b] * py).astype(np.int32)
        gy = np.floor(oy[a:b] + s[a:b] * px + c[a:b] * py).astype(np.int32)
        # Negative indices become huge unsigned ones: one comparison per axis checks both ends.
        inside = (gx.view(np.uint32) < width) & (gy.view(np.uint32) < height)
        flat = gy * width + gx
        np.clip(flat, 0, width * height - 1, out=flat)
        hits = values[flat]
        hits *= inside
        count = inside.sum(axis=1)
        possible[a:b] = count
        np.divide(hits.sum(axis=1, dtype=np.float64), count, out=fractions[a:b], where=count > 0)
    return fractions, possible


def compiled_scoring_pays(particles: int, points: int) -> bool:
    """Whether :func:`hit_fractions` of ``particles`` × ``points`` is worth numba for a caller
    that needs numba for nothing else: from :data:`COMPILED_SCORING_MIN_PAIRS` pairs on. Below,
    the numpy pass takes well under a millisecond, and the process need not load numba and LLVM
    (about 100 MB resident) at all."""
    return particles * points >= COMPILED_SCORING_MIN_PAIRS


#: The compiled scoring of :func:`hit_fractions`, None from ``get()`` without numba.
COMPILED_SCORING = CompiledKernel("easynav.localizers._scoring_numba", "score_kernel")


#: Cell size (m) of :func:`place_clusters`: Nav2's AMCL clusters its particles on 0.5 m cells.
PLACE_CELL = 0.5
#: Above this many cells the clusters' grid is coarsened (a stray particle far away): the
#: labelling's cost follows the grid's size, 47 ms at 4 M cells.
_PLACE_GRID_MAX_CELLS = 1 << 18


def place_clusters(xy: np.ndarray, cell: float = PLACE_CELL) -> np.ndarray:
    """Which place each position belongs to: labels ``0..k-1`` (``(N,)`` int) of the groups of
    ``xy`` (``(N, 2)``) whose ``cell``-sized grid cells are at most two empty cells apart,
    numbered in the order of their first member; a non-finite position is a place of its own.
    One label for a cloud around one place; several when it holds look-alike places (a
    kidnapped robot's redraw) or a global localisation's scatter.

    Why gaps of up to two cells (1 m) bridge: a sparse cloud (100 particles, the original's
    default, spread 2-3 m along a corridor) has gaps between occupied cells; split at them,
    the estimate (:meth:`ParticleFilter2D.estimate`) jumped between the pieces, 3.5 m at
    most, against 1.3 m for the mean of the whole cloud (bridging one empty cell: still
    0.5 m off the cloud's mean at times; two: 0.3 m). Look-alike places a kidnapped robot's
    redraw finds are metres apart."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    labels = np.zeros(len(xy), dtype=np.intp)
    if len(xy) == 0:
        return labels
    low = xy.min(axis=0)
    span = xy.max(axis=0) - low
    if np.all(span < 3.0 * cell):
        # Every position within three cells of every other (finite ones: NaN fails the test):
        # one place, whatever is between them. A compact cloud, the usual case, estimated
        # every RT cycle: no grid to label.
        return labels
    finite = np.isfinite(xy).all(axis=1)
    if not finite.all():
        labels[finite] = place_clusters(xy[finite], cell)
        count = int(labels[finite].max()) + 1 if finite.any() else 0
        labels[~finite] = count + np.arange(int((~finite).sum()))
        return labels
    while (span[0] / cell + 3.0) * (span[1] / cell + 3.0) > _PLACE_GRID_MAX_CELLS:
        cell *= 2.0
    cells = np.floor((xy - low) / cell).astype(np.intp) + 1  # a cell of margin for the bridge
    grid = np.zeros((int(cells[:, 1].max()) + 2, int(cells[:, 0].max()) + 2), dtype=np.uint8)
    grid[cells[:, 1], cells[:, 0]] = 1
    if grid.sum() == 1:
        return labels
    import cv2  # here: OpenCV loads only in processes that estimate from a cloud

    # Each cell grown by one all round: cells with up to two empty cells between them (in any
    # direction, diagonals too) then touch; three do not.
    bridged = cv2.dilate(grid, np.ones((3, 3), np.uint8))
    _, components = cv2.connectedComponents(bridged, connectivity=8)
    found = components[cells[:, 1], cells[:, 0]]
    _, first, relabel = np.unique(found, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first, kind="stable"), kind="stable")
    return order[relabel.reshape(-1)].astype(np.intp)


class ParticleFilter2D:
    """Planar poses ``(x, y, yaw)`` with normalised weights.

    - :meth:`seed`: Gaussian cloud around a pose (full 2×2 position covariance, yaw std).
    - :meth:`predict`: each particle moves by an odometry increment (expressed in the robot's
      previous frame) with zero-mean noise of std ``|dx|·noise_translation``,
      ``|dy|·noise_translation`` and ``|dyaw|·noise_rotation + |d|·noise_translation_to_rotation``
      (the original's motion model).
    - :meth:`correct`: weights are multiplied by each particle's likelihood (Bayes' rule).
    - :meth:`resample`: low-variance (systematic) resampling.
    - :meth:`reseed_worst_half`: the lower-weight half is redrawn around particles of the upper
      half, picked by weight, with the upper half's spread (at least ``min_noise_xy`` and
      ``min_noise_yaw``): the original's way of keeping the cloud alive.

    Thread contract: not locked; the localizer serialises access from its two threads.
    Exceptions: :class:`ValueError` for a particle count < 1 or non-finite seeds.
    """

    def __init__(self, num_particles: int, rng: np.random.Generator | None = None) -> None:
        num_particles = int(num_particles)
        if num_particles < 1:
            raise ValueError(f"num_particles = {num_particles} must be >= 1")
        self.rng = rng if rng is not None else np.random.default_rng()
        self.poses = np.zeros((num_particles, 3))
        self.weights = np.full(num_particles, 1.0 / num_particles)
        #: Particles placed since the last measurement (:meth:`redraw`), left out of
        #: :meth:`estimate` until a measurement weighed them; None when there are none.
        self.unweighed: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.poses)

    # -- sampling -----------------------------------------------------------------------------
    def seed(
        self,
        x: float,
        y: float,
        yaw: float,
        cov_xy: np.ndarray,
        std_yaw: float,
        min_std_xy: float = 0.0,
        min_std_yaw: float = 0.0,
    ) -> None:
        """Draw every particle around ``(x, y, yaw)``; weights become uniform.

        ``cov_xy`` is a 2×2 covariance (negative eigenvalues are clipped); when its mean std is
        below ``min_std_xy`` it is scaled up to it, and the yaw std is at least ``min_std_yaw``.
        """
        if not all(math.isfinite(v) for v in (x, y, yaw, std_yaw)):
            raise ValueError(f"seed pose ({x}, {y}, {yaw}) and std_yaw {std_yaw} must be finite")
        cov = np.asarray(cov_xy, dtype=float).reshape(2, 2)
        if not np.all(np.isfinite(cov)):
            raise ValueError(f"seed covariance must be finite, got {cov.tolist()}")
        cov = 0.5 * (cov + cov.T)
        eigenvalues, eigenvectors = np.linalg.eigh(cov)
        eigenvalues = np.clip(eigenvalues, 0.0, None)
        mean_std = math.sqrt(max(0.5 * eigenvalues.sum(), 0.0))
        if mean_std < min_std_xy:
            if mean_std > 1e-9:
                eigenvalues = eigenvalues * (min_std_xy / mean_std) ** 2
            else:
                eigenvalues = np.full(2, min_std_xy**2)
                eigenvectors = np.eye(2)
        transform = eigenvectors * np.sqrt(eigenvalues)
        n = len(self.poses)
        offsets = self.rng.standard_normal((n, 2)) @ transform.T
        self.poses[:, 0] = x + offsets[:, 0]
        self.poses[:, 1] = y + offsets[:, 1]
        self.poses[:, 2] = _wrap(yaw + max(abs(std_yaw), min_std_yaw) * self.rng.standard_normal(n))
        self.weights[:] = 1.0 / n
        self.unweighed = None

    def predict(
        self,
        dx: float,
        dy: float,
        dyaw: float,
        noise_translation: float,
        noise_rotation: float,
        noise_translation_to_rotation: float,
    ) -> None:
        """Move every particle by the odometry increment ``(dx, dy, dyaw)`` plus noise."""
        n = len(self.poses)
        translation = math.hypot(dx, dy)
        std_yaw = abs(dyaw) * noise_rotation + translation * noise_translation_to_rotation
        noise = self.rng.standard_normal((n, 3))
        ndx = dx + noise[:, 0] * abs(dx) * noise_translation
        ndy = dy + noise[:, 1] * abs(dy) * noise_translation
        ndyaw = dyaw + noise[:, 2] * std_yaw
        c, s = np.cos(self.poses[:, 2]), np.sin(self.poses[:, 2])
        self.poses[:, 0] += c * ndx - s * ndy
        self.poses[:, 1] += s * ndx + c * ndy
        self.poses[:, 2] = _wrap(self.poses[:, 2] + ndyaw)

    # -- weighting ----------------------------------------------------------------------------
    def correct(self, likelihoods: np.ndarray) -> bool:
        """Multiply the weights by ``likelihoods`` (one per particle, >= 0) and normalise.

        Returns False (weights unchanged) when every product is zero: the measurement explains
        no particle, and wiping the belief out would be worse than ignoring it.
        """
        likelihoods = np.asarray(likelihoods, dtype=float)
        if likelihoods.shape != self.weights.shape:
            raise ValueError(
                f"{likelihoods.shape[0] if likelihoods.ndim else 0} likelihoods for "
                f"{len(self.weights)} particles"
            )
        return self.set_weights(self.weights * np.where(np.isfinite(likelihoods), likelihoods, 0.0))

    def set_weights(self, weights: np.ndarray) -> bool:
        """Take ``weights`` (one per particle, >= 0) as the measurement's, normalised: for
        models that weigh from scratch rather than multiply. False (unchanged) when they sum
        to zero."""
        weights = np.asarray(weights, dtype=float)
        if weights.shape != self.weights.shape:
            raise ValueError(f"{len(weights)} weights for {len(self.weights)} particles")
        total = weights.sum()
        if not total > 0.0:
            return False
        self.weights = weights / total
        self.unweighed = None
        return True

    def redraw(self, indices: np.ndarray, poses: np.ndarray) -> None:
        """Put the particles ``indices`` at ``poses`` with the mean weight, and leave them out
        of :meth:`estimate` until the next measurement: not yet weighed, at the mean weight
        they would pull the estimate toward wherever they were drawn (recovery redraws put
        them across the map)."""
        indices = np.asarray(indices, dtype=int)
        poses = np.array(poses, dtype=float).reshape(-1, 3)
        poses[:, 2] = _wrap(poses[:, 2])
        self.poses[indices] = poses
        self.weights[indices] = self.weights.mean()
        self.weights /= self.weights.sum()
        if self.unweighed is None:
            self.unweighed = np.zeros(len(self.poses), dtype=bool)
        self.unweighed[indices] = True

    def effective_sample_size(self) -> float:
        """``1 / Σ w²``: N for uniform weights, 1 when one particle holds them all."""
        return float(1.0 / np.square(self.weights).sum())

    def resample(self, count: int | None = None) -> None:
        """Low-variance resampling: ``count`` (default: the current N) evenly spaced pointers
        with one random offset; a different ``count`` resizes the cloud (KLD sampling)."""
        n = len(self.poses)
        m = n if count is None else int(count)
        if m < 1:
            raise ValueError(f"resample count = {m} must be >= 1")
        positions = (self.rng.random() + np.arange(m)) / m
        cumulative = np.cumsum(self.weights)
        cumulative[-1] = 1.0  # guard against round-off
        indices = np.searchsorted(cumulative, positions, side="right")
        self.poses = self.poses[np.minimum(indices, n - 1)]
        self.weights = np.full(m, 1.0 / m)
        self.unweighed = None

    def replace(self, poses: np.ndarray) -> None:
        """Take ``poses`` (``(M, 3)``) as the cloud, uniform weights (global localisation)."""
        poses = np.array(poses, dtype=float).reshape(-1, 3)
        if len(poses) < 1 or not np.all(np.isfinite(poses)):
            raise ValueError("replacement particles must be finite and at least one")
        poses[:, 2] = _wrap(poses[:, 2])
        self.poses = poses
        self.weights = np.full(len(poses), 1.0 / len(poses))
        self.unweighed = None

    def reseed_worst_half(self, min_noise_xy: float, min_noise_yaw: float) -> None:
        """Redraw the lower-weight half around the upper half (see the class docstring).

        Each copy is jittered with the spread of its own place (:func:`place_clusters`) when
        the upper half lies in several: the spread across places (metres between a kidnapped
        robot's true place and a look-alike) would scatter the copies over the floor between
        them, where neither is."""
        n = len(self.poses)
        if n < 2:
            return
        order = np.argsort(-self.weights, kind="stable")
        top, worst = order[: n // 2 + n % 2], order[n // 2 + n % 2 :]
        top_w = self.weights[top] / self.weights[top].sum()
        std_xy, std_yaw = _spread_per_place(self.poses[top], top_w)
        std_xy = np.maximum(std_xy, min_noise_xy)
        std_yaw = np.maximum(std_yaw, min_noise_yaw)
        positions = (self.rng.random() + np.arange(len(worst))) / len(worst)
        chosen = np.minimum(np.searchsorted(np.cumsum(top_w), positions), len(top) - 1)
        picks = top[chosen]
        noise = self.rng.standard_normal((len(worst), 3))
        self.poses[worst, 0] = self.poses[picks, 0] + std_xy[chosen] * noise[:, 0]
        self.poses[worst, 1] = self.poses[picks, 1] + std_xy[chosen] * noise[:, 1]
        self.poses[worst, 2] = _wrap(self.poses[picks, 2] + std_yaw[chosen] * noise[:, 2])
        self.weights[worst] = self.weights[picks]
        self.weights /= self.weights.sum()

    # -- estimates ----------------------------------------------------------------------------
    def estimate(self) -> tuple[float, float, float]:
        """Weighted mean of the upper-weight half (robust to stray particles), circular for yaw;
        particles not yet weighed (:attr:`unweighed`) count only when no other has weight.

        When the upper half lies in separate places (:func:`place_clusters`: after a kidnapped
        robot's redraw, the true place and a look-alike), the mean of the place holding the
        most weight, as Nav2's AMCL reports its heaviest cluster: a mean across places lies
        in neither. Measured in the depot, which is nearly point-symmetric: 4 % of the cloud
        at the look-alike 14 m away held the mean 0.5 m off the robot for up to 20 s."""
        n = len(self.poses)
        weights = self.weights
        if self.unweighed is not None and len(self.unweighed) == n:
            kept = np.where(self.unweighed, 0.0, weights)
            if kept.sum() > 0.0:
                weights = kept
        # The upper half, ties included: with equal weights (after every resample) the first
        # half of the array is no sample of the cloud (redraws and resampling keep places in
        # runs of indices), and a place with 30 % of the particles held 60 % of it.
        k = max(1, n // 2)
        top = np.flatnonzero(weights >= np.partition(weights, n - k)[n - k])
        w = weights[top]
        if w.sum() > 0.0:
            labels = place_clusters(self.poses[top, :2])
            mass = np.bincount(labels, weights=w)
            if len(mass) > 1:
                keep = labels == int(mass.argmax())
                top, w = top[keep], w[keep]
        w = w / w.sum() if w.sum() > 0.0 else np.full(len(top), 1.0 / len(top))
        x, y = w @ self.poses[top, :2]
        yaw = math.atan2(w @ np.sin(self.poses[top, 2]), w @ np.cos(self.poses[top, 2]))
        return float(x), float(y), float(yaw)

    def covariance(self, mean: tuple[float, float, float] | None = None) -> np.ndarray:
        """3×3 weighted covariance of ``(x, y, yaw)`` over every particle, around ``mean``
        (default: the weighted mean); yaw differences are wrapped to [-π, π)."""
        if mean is None:
            mean = self.estimate()
        d = self.poses - np.asarray(mean, dtype=float)
        d[:, 2] = _wrap(d[:, 2])
        return (self.weights[:, None] * d).T @ d


def _spread_per_place(poses: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each of ``poses`` (``(N, 3)``, weights ``(N,)``), the spreads of its place
    (:func:`place_clusters`), weighted: position ``sqrt(trace(cov) / 2)``, yaw
    ``sqrt(-2 ln R)`` (R the mean resultant length: the original's yaw variance). A place
    without weight counts its members equally."""
    labels = place_clusters(poses[:, :2])
    mass = np.bincount(labels, weights=weights)
    w = np.where(mass[labels] > 0.0, weights, 1.0)
    mass = np.bincount(labels, weights=w)
    mean_x = np.bincount(labels, weights=w * poses[:, 0]) / mass
    mean_y = np.bincount(labels, weights=w * poses[:, 1]) / mass
    square = (poses[:, 0] - mean_x[labels]) ** 2 + (poses[:, 1] - mean_y[labels]) ** 2
    spread_xy = np.sqrt(0.5 * np.bincount(labels, weights=w * square) / mass)
    resultant = np.hypot(np.bincount(labels, weights=w * np.cos(poses[:, 2])),
                         np.bincount(labels, weights=w * np.sin(poses[:, 2]))) / mass
    spread_yaw = np.sqrt(np.maximum(0.0, -2.0 * np.log(np.maximum(resultant, 1e-12))))
    return spread_xy[labels], spread_yaw[labels]
