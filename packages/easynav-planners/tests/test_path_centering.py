"""center_path and ClearanceGradient without ROS, against direct computations."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.planners.path_centering import ClearanceGradient, center_path, resample


def corridor_field(width: float = 1.0, res: float = 0.05) -> ClearanceGradient:
    """A corridor along x, ``width`` wide between walls at y = 0 and y = width: the clearance
    of a cell centre is its distance to the nearer wall."""
    rows = round(width / res)
    y = (np.arange(rows) + 0.5) * res
    clearance = np.minimum(y, width - y)[:, None] * np.ones((1, 120))
    return ClearanceGradient(clearance, 0.0, 0.0, res)


def test_the_field_interpolates_a_linear_clearance_and_its_gradient_exactly():
    res = 0.1
    iy, ix = np.mgrid[0:20, 0:30]
    x, y = (ix + 0.5) * res - 1.0, (iy + 0.5) * res + 2.0
    field = ClearanceGradient(0.3 * x - 0.2 * y + 1.0, -1.0, 2.0, res)
    points = np.array([[-0.73, 2.41], [0.12, 3.07], [1.5, 3.2]])
    value, grad = field.at(points)
    np.testing.assert_allclose(value, 0.3 * points[:, 0] - 0.2 * points[:, 1] + 1.0)
    np.testing.assert_allclose(grad, [[0.3, -0.2]] * 3, atol=1e-12)


def test_resample_spaces_points_evenly_along_the_path_and_keeps_the_ends():
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.55]])
    out = resample(xy, 0.1)
    # 1.55 m in 16 pieces: every point lies on the path at a multiple of 1.55 / 16 from the start.
    s = np.arange(17) * 1.55 / 16
    expected = np.column_stack([np.minimum(s, 1.0), np.maximum(s - 1.0, 0.0)])
    np.testing.assert_allclose(out, expected, atol=1e-12)
    assert out[0].tolist() == [0.0, 0.0] and out[-1].tolist() == [1.0, 0.55]


def test_a_path_hugging_one_wall_moves_to_the_middle_of_a_narrow_corridor():
    # wanted 0.6 m > half the 1 m corridor: the inner poses settle in the middle; the ends stay
    # where they are.
    field = corridor_field()
    xy = np.column_stack([np.linspace(0.5, 5.5, 51), np.full(51, 0.2)])
    out = center_path(xy, field, wanted=0.6, step=0.1)
    assert out[0].tolist() == [0.5, 0.2] and out[-1].tolist() == [5.5, 0.2]
    middle = out[(out[:, 0] > 1.5) & (out[:, 0] < 4.5)]
    assert np.abs(middle[:, 1] - 0.5).max() < 0.005  # settled, not flipping across the middle
    assert np.hypot(*np.diff(out, axis=0).T).max() <= 0.1 + 1e-9


def test_a_path_already_clear_enough_is_not_moved():
    field = corridor_field(width=2.0)
    xy = np.column_stack([np.linspace(0.5, 5.5, 51), np.full(51, 0.9)])
    out = center_path(xy, field, wanted=0.6, step=0.1)
    np.testing.assert_allclose(out, xy, atol=1e-9)


def test_a_path_rounding_a_pillar_keeps_its_side_and_gains_the_wanted_clearance():
    # A pillar (a point obstacle at the origin) in open space; the path passes 0.3 m above it.
    res = 0.05
    iy, ix = np.mgrid[0:80, 0:120]
    x, y = (ix + 0.5) * res - 3.0, (iy + 0.5) * res - 2.0
    field = ClearanceGradient(np.hypot(x, y), -3.0, -2.0, res)
    t = np.linspace(-2.5, 2.5, 51)
    xy = np.column_stack([t, 0.3 + 0.5 * (np.abs(t) > 1.0) * (np.abs(t) - 1.0)])
    out = center_path(xy, field, wanted=0.6, step=0.1)
    distance = np.hypot(out[:, 0], out[:, 1])
    assert (out[:, 1] > 0).all()  # still above the pillar
    assert distance.min() > 0.55
    assert distance.min() > np.hypot(xy[:, 0], xy[:, 1]).min() + 0.2


@pytest.mark.parametrize(("xy", "expected"), [
    (np.zeros((0, 2)), np.zeros((0, 2))),
    (np.array([[1.0, 0.5]]), np.array([[1.0, 0.5]])),
    (np.array([[1.0, 0.5], [1.15, 0.5]]), np.array([[1.0, 0.5], [1.075, 0.5], [1.15, 0.5]])),
])
def test_short_paths_in_the_middle_come_back_resampled(xy, expected):
    out = center_path(xy, corridor_field(), wanted=0.6, step=0.1)
    np.testing.assert_allclose(out, expected, atol=1e-12)


def test_a_grid_too_small_for_a_gradient_is_refused():
    with pytest.raises(ValueError, match="no gradient"):
        ClearanceGradient(np.zeros((1, 5)), 0.0, 0.0, 0.05)
