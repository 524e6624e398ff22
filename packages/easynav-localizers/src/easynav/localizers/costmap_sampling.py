"""Helpers of the costmap AMCL: free-space sampling, the KLD particle count, the beam
likelihood field. Plain numpy (the costmap stack's compiled distance transform, else OpenCV's)
on Costmap2D values, no ROS."""

from __future__ import annotations

import math

import numpy as np

from easynav.localizers.particle_filter import surface_cells

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
    is ``d`` metres from the nearest lethal surface cell (``d`` capped at ``max_dist``; the
    surface, :func:`surface_cells`, where Nav2 takes every lethal cell) has
    ``pz = z_hit·exp(-d²/2σ²) + z_rand/max_range``; the table holds ``pz³`` (Nav2 sums the
    cubes: ``weight = 1 + Σ pz³``, much less peaked than a product over 60 beams). Returns the
    ``(height, width)`` float32 table and the ``pz³`` of a point off the map (``z_rand`` only).

    The distance transform is exact Euclidean: with numba installed the compiled one of the
    costmap inflation (:func:`easynav.maps.inflation.compiled_distances`, exact up to
    ``max_dist``), else OpenCV's (``DIST_MASK_PRECISE``); they agree within a float32
    rounding. The costmap stack loads numba anyway and so does not load OpenCV for this
    (about 20 MB resident, issue #21).
    """
    rand = z_rand / max_range
    obstacles = surface_cells(costmap)
    if obstacles.any():
        from easynav.maps.inflation import compiled_distances

        reach = max_dist / costmap.resolution
        cap = math.ceil(reach) + 1 if math.isfinite(reach) else sum(obstacles.shape)
        cells = compiled_distances(obstacles, cap)
        if cells is None:
            import cv2

            free = (~obstacles).astype(np.uint8)
            cells = cv2.distanceTransform(free, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        d = np.minimum(cells * costmap.resolution, max_dist)
    else:
        d = np.full(obstacles.shape, max_dist, dtype=np.float32)
    pz = z_hit * np.exp(-0.5 * np.square(d / sigma_hit)) + rand
    return (pz**3).astype(np.float32), float(rand**3)


#: Sensor resetting: candidate positions every this many metres, headings every 10°.
RESET_STRIDE = 0.25
RESET_YAW_BINS = 36
#: Scan points scored per coarse candidate (evenly picked): enough to tell places apart.
RESET_POINTS = 60
#: The best coarse candidates refined by a local search (with up to RESET_FINE_POINTS points).
RESET_REFINED = 100
RESET_FINE_POINTS = 180
#: Width (σ, m) of the fine likelihood field the refinement climbs.
RESET_FINE_SIGMA = 0.1
#: Local search steps (m, rad), coarse to fine: each round tries the 3 × 3 × 5 neighbours.
_REFINE_STEPS = ((0.1, math.radians(4.0)), (0.04, math.radians(1.5)), (0.02, math.radians(0.5)))


def _evenly(points_xy: np.ndarray, at_most: int) -> np.ndarray:
    if len(points_xy) <= at_most:
        return points_xy[:, :2]
    return points_xy[np.linspace(0, len(points_xy) - 1, at_most).astype(int), :2]


def _scores(costmap, poses: np.ndarray, points_xy: np.ndarray, field: np.ndarray) -> np.ndarray:
    """The mean field value under the points of each pose; a point off the map is a miss
    (normalised by the points on the map only, a pose at the map's edge with three points on a
    wall and the rest outside scored 1)."""
    from easynav.localizers.particle_filter import hit_fractions

    fractions, inside = hit_fractions(poses, points_xy, costmap, field)
    return fractions * inside / len(points_xy)


def refine_poses(costmap, poses: np.ndarray, points_xy: np.ndarray,
                 field: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each pose moved to the best of its neighbours, coarse to fine (:data:`_REFINE_STEPS`),
    by the scan's fit on ``field``: a scan matcher's local search, vectorised over all poses.
    Returns the refined poses and their scores."""
    poses = np.array(poses, dtype=float)
    offsets = np.array([(dx, dy, da) for dx in (-1, 0, 1) for dy in (-1, 0, 1)
                        for da in (-1.0, -0.5, 0.0, 0.5, 1.0)])
    scores = _scores(costmap, poses, points_xy, field)
    for step_xy, step_yaw in _REFINE_STEPS:
        trial = (poses[:, None, :] + offsets[None, :, :] * (step_xy, step_xy, step_yaw))
        trial_scores = _scores(costmap, trial.reshape(-1, 3), points_xy, field).reshape(
            len(poses), len(offsets))
        pick = trial_scores.argmax(axis=1)
        better = trial_scores[np.arange(len(poses)), pick] > scores
        poses[better] = trial[np.arange(len(poses)), pick][better]
        scores[better] = trial_scores[np.arange(len(poses)), pick][better]
    poses[:, 2] = (poses[:, 2] + math.pi) % (2.0 * math.pi) - math.pi
    return poses, scores


def scan_match(
    costmap,
    points_xy: np.ndarray,
    field: np.ndarray,
    fine_field: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The poses ``(x, y, yaw)`` where the scan fits the map best, best first, with their fits
    (the mean of ``fine_field`` under :data:`RESET_FINE_POINTS` of the points, a point off the
    map a miss): the scan-to-map search of :func:`sensor_reset_poses`, steps 1 and 2.

    Raises:
        ValueError: no free cell, or no points.
    """
    if len(points_xy) == 0:
        raise ValueError("no scan points to reset from")
    ix, iy = free_cells(costmap)
    step = max(1, int(round(RESET_STRIDE / costmap.resolution)))
    keep = (ix % step == 0) & (iy % step == 0)
    ix, iy = ix[keep], iy[keep]
    if len(ix) == 0:
        raise ValueError("the map has no free cell to spread particles over")
    res = costmap.resolution
    x = costmap.origin_x + (ix + 0.5) * res
    y = costmap.origin_y + (iy + 0.5) * res
    yaws = np.linspace(-math.pi, math.pi, RESET_YAW_BINS, endpoint=False)
    candidates = np.column_stack((
        np.repeat(x, RESET_YAW_BINS), np.repeat(y, RESET_YAW_BINS), np.tile(yaws, len(x))))
    scores = _scores(costmap, candidates, _evenly(points_xy, RESET_POINTS), field)
    keep_best = min(RESET_REFINED, len(candidates))
    best = np.argpartition(-scores, keep_best - 1)[:keep_best]
    refined, refined_scores = refine_poses(
        costmap, candidates[best], _evenly(points_xy, RESET_FINE_POINTS),
        field if fine_field is None else fine_field)
    order = np.argsort(-refined_scores, kind="stable")
    return refined[order], refined_scores[order]


def refined_fit(costmap, pose, points_xy: np.ndarray,
                fine_field: np.ndarray) -> tuple[np.ndarray, float]:
    """``pose`` refined by the local search of :func:`scan_match` and its fit, on the same
    points and field: comparable with :func:`scan_match`'s fits (how much worse the scan fits
    where the robot is believed to be than at the best place the search found)."""
    poses, fits = refine_poses(costmap, np.asarray(pose, dtype=float).reshape(1, 3),
                               _evenly(np.asarray(points_xy), RESET_FINE_POINTS), fine_field)
    return poses[0], float(fits[0])


def sensor_reset_poses(
    costmap,
    points_xy: np.ndarray,
    count: int,
    rng: np.random.Generator,
    field: np.ndarray,
    fine_field: np.ndarray | None = None,
    spread: tuple[float, float] = (0.05, 0.02),
) -> np.ndarray:
    """``count`` poses ``(x, y, yaw)`` where the current scan fits the map best: sensor
    resetting (Lenser and Veloso 2000), the recovery of a kidnapped robot that uniform redraws
    cannot give on a large map (on a 30 × 15 m hall, 4000 uniform particles put about one
    within 0.25 m and 10° of the robot).

    1. Every free cell on a :data:`RESET_STRIDE` grid, at :data:`RESET_YAW_BINS` headings, is
       scored on ``field`` (a soft likelihood field,
       :func:`~easynav.localizers.particle_filter.likelihood_field`, about a stride wide, so
       that a candidate half a stride off still scores) with :data:`RESET_POINTS` of
       ``points_xy`` (robot frame; a point off the map is a miss).
    2. The :data:`RESET_REFINED` best are refined by a local search on ``fine_field`` (σ
       :data:`RESET_FINE_SIGMA`; ``field`` when None) with up to :data:`RESET_FINE_POINTS`
       points (:func:`refine_poses`): a candidate 5° off has its far points a metre away from
       their wall and would lose to a worse place; refined, the true place scores best.
    3. The refined poses, best first, are repeated to ``count``, each with Gaussian noise
       ``spread`` (σ m, σ rad).

    Steps 1 and 2 are :func:`scan_match`. Ambiguous places (two corridors alike) all come
    back; the particle filter tells them apart as the robot moves.

    Raises:
        ValueError: no free cell, ``count`` < 1, or no points.
    """
    if count < 1:
        raise ValueError(f"particle count {count} must be >= 1")
    refined, _ = scan_match(costmap, points_xy, field, fine_field)
    return spread_poses(refined, count, rng, spread)


def spread_poses(ranked: np.ndarray, count: int, rng: np.random.Generator,
                 spread: tuple[float, float]) -> np.ndarray:
    """``ranked`` (best first) repeated to ``count`` poses, each with Gaussian noise
    ``spread`` (σ m, σ rad), yaw wrapped to [-π, π)."""
    picks = np.resize(np.asarray(ranked, dtype=float), (count, 3))
    picks[:, :2] += rng.normal(0.0, spread[0], (count, 2))
    picks[:, 2] += rng.normal(0.0, spread[1], count)
    picks[:, 2] = (picks[:, 2] + math.pi) % (2.0 * math.pi) - math.pi
    return picks
