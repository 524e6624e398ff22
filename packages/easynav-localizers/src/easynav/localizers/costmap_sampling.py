"""Helpers of the costmap AMCL: free-space sampling, the KLD particle count, the beam
likelihood field. Plain numpy/OpenCV on Costmap2D values, no ROS."""

from __future__ import annotations

import math

import cv2
import numpy as np

from easynav.localizers.particle_filter import occupied_cells

#: KLD bin sizes (Nav2's AMCL: 0.5 m, 0.5 m, 10°).
KLD_BIN_XY = 0.5
KLD_BIN_YAW = math.radians(10.0)


def free_cells(costmap) -> tuple[np.ndarray, np.ndarray]:
    """``(ix, iy)`` of the free cells (cost 0) of a Costmap2D: where a robot may be."""
    iy, ix = np.nonzero(np.asarray(costmap.data) == 0)
    return ix, iy


def sample_free_space(costmap, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` poses ``(x, y, yaw)`` uniform over the free cells of ``costmap`` (uniform in
    each cell, any yaw): the cloud of a global localisation.

    Raises:
        ValueError: the costmap has no free cell, or ``count`` < 1.
    """
    if count < 1:
        raise ValueError(f"particle count {count} must be >= 1")
    ix, iy = free_cells(costmap)
    if len(ix) == 0:
        raise ValueError("the map has no free cell to spread particles over")
    pick = rng.integers(0, len(ix), count)
    res = costmap.resolution
    x = costmap.origin_x + (ix[pick] + rng.random(count)) * res
    y = costmap.origin_y + (iy[pick] + rng.random(count)) * res
    yaw = rng.uniform(-math.pi, math.pi, count)
    return np.column_stack((x, y, yaw))


def kld_particle_count(
    poses: np.ndarray,
    err: float,
    z: float,
    n_min: int,
    n_max: int,
    bin_xy: float = KLD_BIN_XY,
    bin_yaw: float = KLD_BIN_YAW,
) -> int:
    """Particles needed so that the KL divergence between the sample and the true posterior
    stays below ``err`` with the normal quantile ``z`` (Fox 2003, as Nav2's ``pf_err`` and
    ``pf_z``, ``z`` taken as the quantile value itself like Nav2 does), given the number ``k``
    of occupied ``bin_xy × bin_xy × bin_yaw`` histogram bins; clamped to ``[n_min, n_max]``.
    """
    if len(poses) == 0:
        return n_min
    bins = np.floor(
        np.column_stack((poses[:, 0] / bin_xy, poses[:, 1] / bin_xy, poses[:, 2] / bin_yaw))
    ).astype(np.int64)
    k = len(np.unique(bins, axis=0))
    if k <= 1:
        return n_min
    b = 2.0 / (9.0 * (k - 1))
    n = math.ceil((k - 1) / (2.0 * err) * (1.0 - b + math.sqrt(b) * z) ** 3)
    return int(min(max(n, n_min), n_max))


def beam_likelihood_field(
    costmap, sigma_hit: float, z_hit: float, z_rand: float, max_range: float, max_dist: float
) -> tuple[np.ndarray, float]:
    """Nav2's likelihood-field sensor model as a per-cell table: a point in a cell whose centre
    is ``d`` metres from the nearest lethal cell (``d`` capped at ``max_dist``) has
    ``pz = z_hit·exp(-d²/2σ²) + z_rand/max_range``; the table holds ``pz³`` (Nav2 sums the
    cubes: ``weight = 1 + Σ pz³``, much less peaked than a product over 60 beams). Returns the
    ``(height, width)`` float32 table and the ``pz³`` of a point off the map (``z_rand`` only).

    The distance transform is OpenCV's exact Euclidean one (``DIST_MASK_PRECISE``).
    """
    rand = z_rand / max_range
    obstacles = occupied_cells(costmap)
    if obstacles.any():
        free = (~obstacles).astype(np.uint8)
        d = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE) * costmap.resolution
        d = np.minimum(d, max_dist)
    else:
        d = np.full(obstacles.shape, max_dist, dtype=np.float32)
    pz = z_hit * np.exp(-0.5 * np.square(d / sigma_hit)) + rand
    return (pz**3).astype(np.float32), float(rand**3)
