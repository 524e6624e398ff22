"""Ray casting: Bresenham cells and the clearing of older marks, compiled vs reference."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from easynav.maps.ray_casting import (
    NOT_MARKED,
    clear_along_rays,
    clear_along_rays_reference,
    ray_cells,
)


def test_bresenham_cells_exclude_the_end():
    assert ray_cells(0, 0, 3, 0) == [(0, 0), (1, 0), (2, 0)]
    assert ray_cells(0, 0, 2, 2) == [(0, 0), (1, 1)]
    assert ray_cells(2, 1, 0, 0) == [(2, 1), (1, 1)] or ray_cells(2, 1, 0, 0) == [(2, 1), (1, 0)]
    assert ray_cells(1, 1, 1, 1) == []
    # Every step moves to an 8-neighbour.
    cells = ray_cells(0, 0, 7, -3) + [(7, -3)]
    assert all(max(abs(a - c), abs(b - d)) == 1 for (a, b), (c, d) in pairwise(cells))


def test_only_older_marks_on_the_way_are_cleared():
    marks = np.full((5, 10), NOT_MARKED)
    marks[2, 4] = 1.0  # older: a person who walked away
    marks[2, 6] = 3.0  # newer than the beam: kept
    marks[2, 8] = 1.0  # the hit cell itself: kept
    marks[3, 4] = 1.0  # beside the beam: kept
    removed = clear_along_rays(marks, (0, 2), np.array([8]), np.array([2]), 2.0, 100.0)
    assert removed == 1
    assert marks[2, 4] == NOT_MARKED and marks[2, 6] == 3.0 and marks[2, 8] == 1.0
    assert marks[3, 4] == 1.0


def test_range_limit_and_rays_leaving_the_grid():
    marks = np.full((3, 10), 0.0)
    clear_along_rays(marks, (0, 1), np.array([1000]), np.array([1]), 1.0, 3.0)
    assert (marks[1, :4] == NOT_MARKED).all() and (marks[1, 4:] == 0.0).all()
    marks = np.full((3, 10), 0.0)
    clear_along_rays(marks, (-5, 1), np.array([3]), np.array([1]), 1.0, 100.0)
    assert (marks[1, :3] == NOT_MARKED).all() and marks[1, 3] == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_compiled_matches_reference(seed):
    rng = np.random.default_rng(seed)
    marks = np.where(rng.random((40, 50)) < 0.3, rng.uniform(0, 2, (40, 50)), NOT_MARKED)
    ends_x = rng.integers(-10, 60, 200)
    ends_y = rng.integers(-10, 50, 200)
    origin = (int(rng.integers(0, 50)), int(rng.integers(0, 40)))
    a, b = marks.copy(), marks.copy()
    n_a = clear_along_rays(a, origin, ends_x, ends_y, 1.0, 25.0)
    n_b = clear_along_rays_reference(b, origin, ends_x, ends_y, 1.0, 25.0)
    assert n_a == n_b and np.array_equal(a, b)
