"""Inflation against direct computations of the original's (Nav2's) formula: 254 on a lethal
cell, 253 within the inscribed radius, int(252·exp(-k·(d - inscribed))) up to the inflation
radius."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.maps.inflation import (
    cell_inflation_radius,
    inflate,
    inflate_reference,
    inflation_cost,
)


def test_costs_at_known_distances():
    # res 0.05, inscribed 0.25, k 3: 254 on the obstacle, 253 up to 5 cells, then the decay.
    data = np.zeros((1, 20), dtype=np.uint8)
    data[0, 0] = 254
    out = inflate(data, 0.05, 0.6, 0.25, 3.0)
    expected = [254, 253, 253, 253, 253, 253]
    for d in range(6, 13):
        expected.append(int(252 * math.exp(-3.0 * (d * 0.05 - 0.25))))
    expected += [0] * (20 - len(expected))
    assert out[0].tolist() == expected
    assert expected[6] == 216 and expected[12] == 88  # 252·e^(-0.15), 252·e^(-1.05)


def test_radius_is_rounded_up_to_whole_cells():
    assert cell_inflation_radius(0.3, 0.05) == 6
    assert cell_inflation_radius(0.32, 0.05) == 7
    assert cell_inflation_radius(0.0, 0.05) == 0
    data = np.zeros((1, 12), dtype=np.uint8)
    data[0, 0] = 254
    out = inflate(data, 0.05, 0.32, 0.1, 3.0)
    assert out[0, 7] == inflation_cost(7, 0.05, 0.1, 3.0) > 0 and out[0, 8] == 0


def test_diagonal_distances_are_euclidean():
    data = np.zeros((10, 10), dtype=np.uint8)
    data[0, 0] = 254
    out = inflate(data, 0.1, 1.0, 0.1, 2.0)
    assert out[3, 4] == inflation_cost(5.0, 0.1, 0.1, 2.0)
    assert out[7, 7] == inflation_cost(math.hypot(7, 7), 0.1, 0.1, 2.0) > 0  # 9.9 cells
    assert out[8, 7] == 0  # 10.6 cells: beyond the 10-cell radius


def test_unknown_cells_take_only_inscribed_costs():
    data = np.full((1, 10), 255, dtype=np.uint8)
    data[0, 0] = 254
    out = inflate(data, 0.1, 1.0, 0.25, 3.0)
    assert out[0].tolist() == [254, 253, 253] + [255] * 7


def test_old_costs_kept_when_higher():
    data = np.array([[254, 0, 0, 0, 240, 0]], dtype=np.uint8)
    out = inflate(data, 0.1, 0.5, 0.05, 3.0)
    assert out[0, 4] == 240 and out[0, 5] == max(0, inflation_cost(5, 0.1, 0.05, 3.0))


@pytest.mark.parametrize("seed", range(6))
def test_matches_brute_force_on_random_maps(seed):
    rng = np.random.default_rng(seed)
    shape = (int(rng.integers(5, 30)), int(rng.integers(5, 30)))
    data = np.zeros(shape, dtype=np.uint8)
    data[rng.random(shape) < 0.05] = 254
    data[rng.random(shape) < 0.1] = 255
    data[rng.random(shape) < 0.1] = rng.integers(1, 253)
    resolution = float(rng.choice([0.05, 0.1, 0.2]))
    radius = float(rng.uniform(0.0, 1.2))
    inscribed = float(rng.uniform(0.0, radius))
    k = float(rng.uniform(0.5, 10.0))
    expected = inflate_reference(data, resolution, radius, inscribed, k)
    assert np.array_equal(inflate(data, resolution, radius, inscribed, k), expected)


def test_no_lethal_cells_leave_the_map_unchanged():
    data = np.array([[0, 10, 255]], dtype=np.uint8)
    assert inflate(data, 0.05, 0.3, 0.2, 3.0).tolist() == data.tolist()


@pytest.mark.parametrize("seed", range(4))
def test_compiled_and_opencv_paths_agree(seed):
    from easynav.maps import inflation

    if not inflation.compiled():
        pytest.skip("numba not installed: only the OpenCV path exists")
    rng = np.random.default_rng(100 + seed)
    shape = (int(rng.integers(1, 120)), int(rng.integers(1, 120)))
    data = np.zeros(shape, dtype=np.uint8)
    density = float(rng.choice([0.0, 0.002, 0.02, 0.3, 0.7]))
    data[rng.random(shape) < density] = 254
    data[rng.random(shape) < 0.05] = 255
    cap = int(rng.integers(1, 30))
    table = inflation.inflation_cost_table(cap, 0.05, 0.1, 3.0)
    compiled = inflation.inflation_costs(data, cap, table)
    assert np.array_equal(compiled, inflation.inflation_costs_opencv(data, cap, table))
    combined = inflation.inflate(data, 0.05, cap * 0.05, 0.1, 3.0)
    assert np.array_equal(combined, inflation.combine_costs(data, compiled))


def test_walls_rows_use_the_envelope_and_match_brute_force():
    # Long free runs (large column distances) take the lower-envelope branch.
    data = np.zeros((40, 60), dtype=np.uint8)
    data[0, :] = 254
    data[:, 30] = 254
    data[25, 5] = 254
    expected = inflate_reference(data, 0.05, 1.0, 0.2, 2.0)
    assert np.array_equal(inflate(data, 0.05, 1.0, 0.2, 2.0), expected)


@pytest.mark.parametrize("seed", range(6))
def test_compiled_distances_are_exact_within_the_cap_and_agree_with_opencv(seed):
    # The costmap AMCL's likelihood field uses this transform instead of OpenCV's when numba is
    # installed (the costmap stack then need not load OpenCV, issue #21).
    import cv2

    from easynav.maps import inflation

    if not inflation.compiled():
        pytest.skip("numba not installed: callers use OpenCV's transform")
    rng = np.random.default_rng(300 + seed)
    shape = (int(rng.integers(1, 70)), int(rng.integers(1, 70)))
    obstacles = rng.random(shape) < float(rng.choice([0.002, 0.02, 0.3]))
    obstacles[int(rng.integers(shape[0])), int(rng.integers(shape[1]))] = True
    cap = int(rng.choice([1, 4, 15, 1000]))
    distances = inflation.compiled_distances(obstacles, cap)
    assert distances.dtype == np.float32 and distances.shape == shape
    oy, ox = np.nonzero(obstacles)
    yy, xx = np.mgrid[0 : shape[0], 0 : shape[1]]
    squared = ((yy[..., None] - oy) ** 2 + (xx[..., None] - ox) ** 2).min(axis=2)
    within = squared <= cap * cap
    assert np.array_equal(distances[within], np.sqrt(squared[within].astype(np.float32)))
    assert (distances[~within] > cap).all()
    opencv = cv2.distanceTransform((~obstacles).astype(np.uint8), cv2.DIST_L2,
                                   cv2.DIST_MASK_PRECISE)
    # OpenCV's float square root may differ by one float32 rounding.
    np.testing.assert_allclose(distances[within], opencv[within], rtol=2.5e-7, atol=0.0)
