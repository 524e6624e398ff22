"""Ray casting against the grid and discs, checked against a brute-force ray march; the
compiled grid caster also against its numpy reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.playground.sim import World, cast_rays_discs, cast_rays_grid
from easynav.playground.sim.ray_casting import _compiled_caster, cast_rays_grid_reference

MARCH_STEP = 0.0002


def march(world, x, y, angles, max_range, discs=()):
    """Reference: walk each ray in tiny steps and stop at the first occupied point."""
    t = np.arange(0.0, max_range, MARCH_STEP)
    px = x + np.cos(angles)[:, None] * t
    py = y + np.sin(angles)[:, None] * t
    hit = world.is_occupied_at(px, py)
    for (cx, cy), r in discs:
        hit |= np.hypot(px - cx, py - cy) <= r
    return np.where(hit.any(axis=1), t[np.argmax(hit, axis=1)], np.inf)


#: Both grid casters: the one the simulator uses (compiled with numba) and its reference.
GRID_CASTERS = pytest.mark.parametrize(
    "cast", [cast_rays_grid, cast_rays_grid_reference], ids=["compiled", "reference"])


@pytest.fixture(scope="module")
def sandbox():
    return World.load("/work/shared/maps/tb3_sandbox.yaml")


@GRID_CASTERS
def test_grid_ray_cast_matches_brute_force_on_a_real_map(cast, sandbox):
    rng = np.random.default_rng(7)
    free = np.argwhere(~sandbox.occupied)
    for _ in range(15):
        iy, ix = free[rng.integers(len(free))]
        x, y = sandbox.cell_centre(ix, iy)
        x += rng.uniform(-0.02, 0.02)
        y += rng.uniform(-0.02, 0.02)
        angles = rng.uniform(-math.pi, math.pi, 64)
        fast = cast(sandbox, x, y, angles, 4.0)
        slow = march(sandbox, x, y, angles, 4.0)
        assert np.array_equal(np.isinf(fast), np.isinf(slow))
        finite = np.isfinite(fast)
        assert np.max(np.abs(fast[finite] - slow[finite]), initial=0.0) <= MARCH_STEP + 1e-9


@GRID_CASTERS
def test_axis_aligned_rays_hit_the_wall_face_exactly(cast):
    grid = np.zeros((20, 20), dtype=bool)
    grid[:, 15] = True  # wall whose west face is x = 1.5
    world = World(grid, 0.1)
    d = cast(world, 0.52, 1.0, np.array([0.0, math.pi, math.pi / 2]), 5.0)
    assert d[0] == pytest.approx(1.5 - 0.52)
    assert d[1] == np.inf and d[2] == np.inf  # leaves the grid: no return


@GRID_CASTERS
def test_ray_from_outside_the_grid_still_finds_it(cast):
    grid = np.zeros((10, 10), dtype=bool)
    grid[5, 5] = True
    world = World(grid, 0.1, 0.0, 0.0)
    d = cast(world, -3.0, 0.55, np.array([0.0]), 10.0)
    assert d[0] == pytest.approx(3.5)


@GRID_CASTERS
def test_max_range_cuts_returns(cast, sandbox):
    d = cast(sandbox, 0.0, 0.5, np.linspace(-math.pi, math.pi, 90), 0.3)
    assert np.all(np.isinf(d) | (d <= 0.3))


def test_disc_ray_cast_matches_brute_force():
    world = World(np.zeros((1, 1), dtype=bool), 0.01, -100.0, -100.0)
    discs = [((1.0, 0.2), 0.3), ((-0.5, -1.0), 0.25)]
    angles = np.linspace(-math.pi, math.pi, 200, endpoint=False)
    fast = cast_rays_discs(0.0, 0.0, angles, [c for c, _ in discs], [r for _, r in discs])
    slow = march(world, 0.0, 0.0, angles, 3.0, discs)
    assert np.array_equal(np.isinf(fast), np.isinf(slow))
    finite = np.isfinite(fast)
    assert finite.sum() > 10
    assert np.max(np.abs(fast[finite] - slow[finite])) <= MARCH_STEP + 1e-9


def test_ray_starting_inside_a_disc_has_zero_range_and_discs_behind_are_ignored():
    d = cast_rays_discs(0.0, 0.0, np.array([0.0, math.pi]), [(0.0, 0.0)], [0.5])
    assert d.tolist() == [0.0, 0.0]
    d = cast_rays_discs(0.0, 0.0, np.array([0.0]), [(-2.0, 0.0)], [0.5])
    assert d[0] == np.inf


def test_compiled_grid_caster_equals_its_reference():
    # Random grids, origins (outside the grid too) and ranges; rays at every degree and at
    # random angles. Origins are generic: on a ray through a cell corner to within rounding,
    # which side cell the two see is a matter of the last bit.
    if _compiled_caster() is None:
        pytest.skip("numba is not installed: the reference is the caster")
    rng = np.random.default_rng(1)
    for _ in range(100):
        h, w = rng.integers(5, 60, 2)
        world = World(rng.random((h, w)) < rng.uniform(0.02, 0.3), 0.05,
                      rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0))
        x = world.origin_x + rng.uniform(-0.5, w * 0.05 + 0.5)
        y = world.origin_y + rng.uniform(-0.5, h * 0.05 + 0.5)
        angles = np.concatenate((np.linspace(-math.pi, math.pi, 360, endpoint=False),
                                 rng.uniform(-4.0, 4.0, 50)))
        reach = float(rng.uniform(0.1, 4.0))
        compiled = cast_rays_grid(world, x, y, angles, reach)
        reference = cast_rays_grid_reference(world, x, y, angles, reach)
        assert np.array_equal(np.isinf(compiled), np.isinf(reference))
        finite = np.isfinite(reference)
        assert np.max(np.abs(compiled[finite] - reference[finite]), initial=0.0) < 1e-9


@GRID_CASTERS
def test_a_ray_backwards_from_a_grid_line_starts_in_the_cell_behind_it(cast):
    grid = np.zeros((1, 10), dtype=bool)
    grid[0, 4] = True  # the cell [4, 5): its east face is the line x = 5
    world = World(grid, 1.0)
    assert cast(world, 5.0, 0.5, np.array([math.pi]), 20.0)[0] == 0.0
    assert cast(world, 5.0, 0.5, np.array([0.0]), 20.0)[0] == np.inf


@GRID_CASTERS
def test_non_finite_origins_and_angles_hit_nothing(cast):
    # The compiled traversal looped for ever on a NaN or infinite origin (no crossing ends it).
    grid = np.zeros((10, 10), dtype=bool)
    grid[5, 5] = True
    world = World(grid, 0.1)
    for x, y in ((math.nan, 0.55), (math.inf, 0.55), (-math.inf, 0.55), (0.55, math.inf)):
        assert np.all(np.isinf(cast(world, x, y, np.array([0.0, math.pi, 1.0]), 5.0)))
    assert cast(world, -3.0, 0.55, np.array([0.0, math.nan]), 10.0)[1] == np.inf


def test_bad_max_range_or_angles_are_refused():
    world = World(np.zeros((10, 10), dtype=bool), 0.1)
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="max_range"):
            cast_rays_grid(world, 0.5, 0.5, np.array([0.0]), bad)
    with pytest.raises(ValueError, match="1-D"):
        cast_rays_grid(world, 0.5, 0.5, np.zeros((2, 3)), 1.0)
