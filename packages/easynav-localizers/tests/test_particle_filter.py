"""ParticleFilter2D and hit_fractions: sampling, motion, weighting, resampling, estimates."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.localizers import ParticleFilter2D, hit_fractions
from easynav.localizers.particle_filter import place_clusters
from easynav.maps import SimpleMap


def filter_with(n=4000, seed=0) -> ParticleFilter2D:
    return ParticleFilter2D(n, np.random.default_rng(seed))


def test_seed_draws_the_requested_gaussian():
    pf = filter_with()
    cov = np.array([[0.09, 0.03], [0.03, 0.04]])
    pf.seed(1.0, -2.0, 3.0, cov, 0.2)
    assert pf.poses[:, :2].mean(axis=0) == pytest.approx([1.0, -2.0], abs=0.02)
    assert np.cov(pf.poses[:, :2].T) == pytest.approx(cov, abs=0.01)
    yaw_dev = np.remainder(pf.poses[:, 2] - 3.0 + np.pi, 2 * np.pi) - np.pi
    assert yaw_dev.std() == pytest.approx(0.2, abs=0.01)
    assert np.all(np.abs(pf.poses[:, 2]) <= np.pi)  # wrapped
    assert pf.weights.sum() == pytest.approx(1.0)


def test_seed_enforces_minimum_noise():
    pf = filter_with()
    pf.seed(0.0, 0.0, 0.0, np.zeros((2, 2)), 0.0, min_std_xy=0.05, min_std_yaw=0.05)
    assert pf.poses[:, 0].std() == pytest.approx(0.05, rel=0.1)
    assert pf.poses[:, 2].std() == pytest.approx(0.05, rel=0.1)
    with pytest.raises(ValueError, match="must be finite"):
        pf.seed(float("nan"), 0.0, 0.0, np.eye(2), 0.1)


def test_predict_composes_the_increment_in_each_particle_frame():
    pf = filter_with(2)
    pf.poses[:] = [[0.0, 0.0, 0.0], [1.0, 1.0, math.pi / 2]]
    pf.predict(1.0, 0.5, 0.1, 0.0, 0.0, 0.0)
    assert pf.poses[0] == pytest.approx([1.0, 0.5, 0.1])
    assert pf.poses[1] == pytest.approx([0.5, 2.0, math.pi / 2 + 0.1])


def test_predict_noise_grows_with_motion():
    pf = filter_with()
    pf.seed(0.0, 0.0, 0.0, np.zeros((2, 2)), 0.0)
    pf.predict(0.0, 0.0, 0.0, 0.1, 0.1, 0.1)
    assert np.all(pf.poses == 0.0)  # no motion, no noise: the original's model
    pf.predict(1.0, 0.0, 0.5, 0.1, 0.2, 0.1)
    assert pf.poses[:, 0].std() == pytest.approx(0.1, rel=0.1)
    assert pf.poses[:, 2].std() == pytest.approx(0.5 * 0.2 + 1.0 * 0.1, rel=0.1)


def test_correct_and_low_variance_resampling():
    pf = filter_with(1000)
    pf.poses[:, 0] = np.arange(1000) % 4  # four groups
    likelihood = np.where(pf.poses[:, 0] == 2, 3.0, 1.0)
    assert pf.correct(likelihood)
    assert pf.weights[pf.poses[:, 0] == 2].sum() == pytest.approx(0.5)
    assert pf.effective_sample_size() < 1000
    pf.resample()
    counts = np.bincount(pf.poses[:, 0].astype(int), minlength=4)
    assert counts.tolist() == [167, 167, 500, 166] or abs(counts[2] - 500) <= 1
    assert np.all(pf.weights == 1e-3)


def test_correct_with_no_support_keeps_the_belief():
    pf = filter_with(10)
    before = pf.weights.copy()
    assert not pf.correct(np.zeros(10))
    assert np.array_equal(pf.weights, before)
    with pytest.raises(ValueError, match="3 likelihoods for 10 particles"):
        pf.correct(np.ones(3))


def test_reseed_redraws_the_worse_half_near_the_better():
    pf = filter_with(200)
    pf.poses[:100] = [5.0, 5.0, 1.0]
    pf.poses[100:] = [-5.0, -5.0, -1.0]
    pf.weights[:100], pf.weights[100:] = 0.009, 0.001
    pf.reseed_worst_half(0.05, 0.05)
    assert np.all(np.hypot(pf.poses[:, 0] - 5.0, pf.poses[:, 1] - 5.0) < 0.3)
    assert pf.weights.sum() == pytest.approx(1.0)


def test_estimate_uses_circular_yaw_and_covariance_wraps():
    pf = filter_with(4)
    pf.poses[:] = [
        [0, 0, math.pi - 0.1],
        [0, 0, -math.pi + 0.1],
        [0, 0, math.pi - 0.1],
        [0, 0, -math.pi + 0.1],
    ]
    x, y, yaw = pf.estimate()
    assert abs(abs(yaw) - math.pi) < 1e-9
    assert pf.covariance()[2, 2] == pytest.approx(0.01)


def test_hit_fractions_match_a_plain_loop():
    rng = np.random.default_rng(3)
    grid = SimpleMap(40, 30, 0.1, -1.0, -2.0, rng.random((30, 40)) < 0.3)
    poses = np.column_stack(
        (rng.uniform(-1, 3, 50), rng.uniform(-2, 1, 50), rng.uniform(-4, 4, 50))
    )
    points = rng.uniform(-2.0, 2.0, (60, 2))
    fractions, possible = hit_fractions(poses, points, grid, chunk=7)
    for i, (x, y, yaw) in enumerate(poses):
        c, s = math.cos(yaw), math.sin(yaw)
        wx = x + c * points[:, 0] - s * points[:, 1]
        wy = y + s * points[:, 0] + c * points[:, 1]
        inside = grid.contains(wx, wy)
        assert possible[i] == inside.sum()
        expected = grid.occupied_at(wx, wy)[inside].mean() if inside.any() else 0.0
        assert fractions[i] == pytest.approx(expected)


def test_bad_particle_count():
    with pytest.raises(ValueError, match="num_particles = 0"):
        ParticleFilter2D(0)


def test_likelihood_field_counts_near_misses_softly():
    from easynav.localizers import likelihood_field

    grid = SimpleMap(20, 1, 0.1)
    grid.cells[0, 10] = True
    field = likelihood_field(grid, 0.2)
    assert field[0, 10] == 1.0
    assert field[0, 12] == pytest.approx(math.exp(-0.5 * (0.2 / 0.2) ** 2), rel=1e-5)
    assert field[0, 0] < 0.01
    assert np.array_equal(likelihood_field(grid, 0.0), grid.cells.astype(np.float32))
    fractions, _ = hit_fractions(
        np.zeros((1, 3)), np.array([[1.05, 0.05], [1.25, 0.05]]), grid, field
    )
    assert fractions[0] == pytest.approx((1.0 + field[0, 12]) / 2)
    with pytest.raises(ValueError, match="hit sigma = -1"):
        likelihood_field(grid, -1.0)


def test_redrawn_particles_count_in_the_estimate_once_weighed():
    # The cloud on (1, 1); a quarter redrawn at (9, 9), as a recovery redraw would: at the mean
    # weight they would pull the estimate 2 m toward (9, 9) before any scan had weighed them.
    pf = filter_with(400)
    pf.poses[:] = (1.0, 1.0, 0.0)
    pf.redraw(np.arange(100), np.tile((9.0, 9.0, 0.0), (100, 1)))
    assert pf.poses[:100, 0].tolist() == [9.0] * 100
    assert pf.weights.sum() == pytest.approx(1.0)
    assert pf.estimate() == pytest.approx((1.0, 1.0, 0.0))
    # The next measurement weighs them: where it favours them, the estimate follows (to the
    # place with the most weight: the upper half holds both places, 100 × 100 against 100 × 1).
    assert pf.correct(np.where(pf.poses[:, 0] == 9.0, 100.0, 1.0))
    assert pf.unweighed is None
    assert pf.estimate()[0] == pytest.approx(9.0)
    # Weights from scratch (set_weights) weigh them too; resampling forgets the mark.
    pf.redraw(np.arange(300, 400), np.tile((5.0, 5.0, 0.0), (100, 1)))
    assert pf.estimate()[0] == pytest.approx(9.0)
    assert pf.set_weights(np.where(pf.poses[:, 0] == 5.0, 1.0, 0.0))
    assert pf.estimate()[0] == pytest.approx(5.0)
    pf.redraw(np.arange(10), np.zeros((10, 3)))
    pf.resample()
    assert pf.unweighed is None
    # Only unweighed particles carry weight: they are the estimate (nothing else to go by).
    pf.poses[:] = (2.0, 2.0, 0.0)
    pf.weights[:] = 0.0
    pf.weights[0] = 1.0
    pf.redraw(np.array([0]), np.array([[3.0, 3.0, 0.0]]))
    assert pf.estimate() == pytest.approx((3.0, 3.0, 0.0))


def test_compiled_scoring_pays_from_the_threshold_on():
    from easynav.localizers.particle_filter import COMPILED_SCORING_MIN_PAIRS, compiled_scoring_pays

    assert not compiled_scoring_pays(1, COMPILED_SCORING_MIN_PAIRS - 1)
    assert compiled_scoring_pays(1, COMPILED_SCORING_MIN_PAIRS)
    assert not compiled_scoring_pays(0, 10**9)


def filled_block_map() -> SimpleMap:
    """8 x 8 m at 0.1 m: a building drawn as a filled block (x 2..6, y 2..6) and a wall 0.2 m
    thick along the map's left edge."""
    grid = SimpleMap(80, 80, 0.1)
    grid.cells[20:60, 20:60] = True
    grid.cells[:, 0:2] = True
    return grid


def test_surface_cells_keep_the_faces_of_a_filled_block_and_whole_walls():
    from easynav.localizers.particle_filter import SURFACE_DEPTH, surface_cells

    grid = filled_block_map()
    surface = surface_cells(grid)
    skin = round(SURFACE_DEPTH / grid.resolution)  # 3 cells
    assert surface[:, 0:2].all()  # a thin wall (and the map's edge) is all surface
    block = surface[20:60, 20:60]
    assert block[:skin, :].all() and block[-skin:, :].all()
    assert block[:, :skin].all() and block[:, -skin:].all()
    assert not block[skin:-skin, skin:-skin].any()  # the inside a laser never reaches
    assert not (surface & ~grid.cells).any()
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(ValueError, match="surface depth"):
            surface_cells(grid, bad)


def test_a_scan_that_lands_inside_a_filled_block_no_longer_fits():
    from easynav.localizers import likelihood_field

    grid = filled_block_map()
    # The robot at (0.5, 4) facing the block: its points on the block's face at x = 2.
    truth = np.array([[0.5, 4.0, 0.0]])
    points = np.column_stack((np.full(31, 1.5), np.linspace(-1.5, 1.5, 31)))
    too_close = truth + [1.6, 0.0, 0.0]  # the same points 1.6 m inside the block
    for field in (None, likelihood_field(grid, 0.2)):
        at_truth, _ = hit_fractions(truth, points, grid, field)
        inside, _ = hit_fractions(too_close, points, grid, field)
        assert at_truth[0] > 0.95
        # Every occupied cell counted, this scored 1.0 as well; now only the points that land
        # near the block's other faces (its ends at y 2 and 6) count, a little.
        assert inside[0] < 0.1


def test_place_clusters_group_touching_cells():
    xy = np.array([[0.0, 0.0], [0.3, 0.2], [0.9, 0.4], [5.0, 5.0], [5.2, 4.9], [1.4, 0.6]])
    # 0.5 m cells: the first three and the last touch (cells (0,0), (1,0), (2,1)); the two at
    # (5, 5) are another place.
    assert place_clusters(xy).tolist() == [0, 0, 0, 1, 1, 0]
    assert place_clusters(xy[:1]).tolist() == [0]
    assert place_clusters(np.zeros((0, 2))).tolist() == []
    # A cloud over a huge span still clusters (on a coarser grid), in bounded memory.
    assert place_clusters(np.array([[0.0, 0.0], [1e6, 1e6], [0.1, 0.0]])).tolist() == [0, 1, 0]


def test_estimate_is_the_heaviest_place_not_the_mean_between_places():
    # A kidnapped robot's cloud after a redraw: most weight at (8, 6), a look-alike at
    # (22, 9) facing the other way. The mean of the upper half lay between them, 0.5 m off
    # with 4 % at the look-alike; the estimate is the heavier place's.
    rng = np.random.default_rng(0)
    pf = filter_with(1000)
    pf.poses[:960] = (8.0, 6.0, math.pi) + rng.normal(0.0, 0.05, (960, 3))
    pf.poses[960:] = (22.0, 9.0, 0.0) + rng.normal(0.0, 0.05, (40, 3))
    pf.weights[:] = 1.0 / 1000
    x, y, yaw = pf.estimate()
    assert math.hypot(x - 8.0, y - 6.0) < 0.01
    assert abs(abs(yaw) - math.pi) < 0.01
    # The heavier place wins even when it holds fewer particles.
    pf.weights[:960] = 0.1 / 960
    pf.weights[960:] = 0.9 / 40
    x, y, _ = pf.estimate()
    assert math.hypot(x - 22.0, y - 9.0) < 0.02


def test_reseed_keeps_each_copy_at_its_own_place():
    # Two places 14 m apart in the upper half: the copies are jittered with their place's
    # spread (here the floor min_noise_xy), not with the 7 m spread across both places.
    rng = np.random.default_rng(1)
    pf = filter_with(2000)
    pf.poses[:600] = (8.0, 6.0, 0.0) + rng.normal(0.0, 0.05, (600, 3))
    pf.poses[600:1000] = (22.0, 9.0, 0.0) + rng.normal(0.0, 0.05, (400, 3))
    pf.poses[1000:] = (15.0, 1.0, 0.0)
    pf.weights[:1000] = 1.0
    pf.weights[1000:] = 0.001
    pf.weights /= pf.weights.sum()
    pf.reseed_worst_half(0.05, 0.05)
    near = np.minimum(np.hypot(pf.poses[:, 0] - 8.0, pf.poses[:, 1] - 6.0),
                      np.hypot(pf.poses[:, 0] - 22.0, pf.poses[:, 1] - 9.0))
    assert near.max() < 0.6
    at_first = np.hypot(pf.poses[1000:, 0] - 8.0, pf.poses[1000:, 1] - 6.0) < 0.6
    assert 0.5 < at_first.mean() < 0.7  # copies picked by weight: 600 of 1000
    # One place: the original's reseed (the upper half's spread, floored).
    pf.poses[:1000] = (8.0, 6.0, 0.0) + rng.normal(0.0, 0.3, (1000, 3))
    pf.poses[1000:] = (15.0, 1.0, 0.0)
    pf.weights[:] = np.where(np.arange(2000) < 1000, 1.0, 0.001)
    pf.weights /= pf.weights.sum()
    pf.reseed_worst_half(0.05, 0.05)
    spread = np.hypot(pf.poses[1000:, 0] - 8.0, pf.poses[1000:, 1] - 6.0)
    assert 0.3 < np.median(spread) < 0.8


def test_estimate_with_equal_weights_weighs_every_place_by_its_particles():
    # After a resample every weight is equal; the redrawn place sits at the low indices. The
    # first half of the array held 60 % of this place with 30 % of the particles and the
    # estimate went there; ties in the upper half count, so the larger place wins.
    pf = filter_with(1000)
    pf.poses[:300] = (22.0, 9.0, 0.0)
    pf.poses[300:] = (8.0, 6.0, 0.0)
    pf.weights[:] = 1.0 / 1000
    assert pf.estimate() == pytest.approx((8.0, 6.0, 0.0))


def test_a_sparse_cloud_along_a_corridor_is_one_place():
    # 100 particles (the original's default count) spread 2 m along a corridor: the estimate
    # stays on the whole upper half's mean, not on a fragment of it, whatever the weights.
    rng = np.random.default_rng(0)
    pf = filter_with(100)
    pf.poses[:, :2] = rng.normal(0.0, (2.0, 0.1), (100, 2))
    pf.poses[:, 2] = 0.0
    off = []
    for _ in range(200):
        weights = rng.random(100)
        pf.weights = weights / weights.sum()
        top = np.argsort(-pf.weights)[:50]
        mean = pf.weights[top] @ pf.poses[top, 0] / pf.weights[top].sum()
        off.append(abs(pf.estimate()[0] - mean))
    assert np.median(off) < 1e-9 and max(off) < 0.5


def test_place_clusters_bridge_two_empty_cells_and_set_non_finite_apart():
    # Two cells at every offset up to 4 cells: one place up to two empty cells between them.
    for dx in range(-4, 5):
        for dy in range(-4, 5):
            if dx or dy:
                xy = np.array([[5.1, 5.1], [5.1 + 0.5 * dx, 5.1 + 0.5 * dy]])
                apart = max(abs(dx), abs(dy)) > 3
                assert place_clusters(xy).tolist() == ([0, 1] if apart else [0, 0]), (dx, dy)
    assert place_clusters(np.array([[0.0, 0.0], [np.nan, 1.0], [0.1, 0.0]])).tolist() == [0, 1, 0]
