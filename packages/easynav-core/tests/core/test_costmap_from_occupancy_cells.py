"""Costmap2D.from_occupancy_cells: a boolean occupancy grid as lethal and free cells."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from easynav.core.types import FREE_SPACE, LETHAL_OBSTACLE, Costmap2D


def test_occupied_cells_become_lethal_the_others_free():
    cells = np.zeros((3, 4), dtype=bool)
    cells[1, 2] = True
    grid = SimpleNamespace(cells=cells, resolution=0.1, origin_x=-1.0, origin_y=-2.0)
    costmap = Costmap2D.from_occupancy_cells(grid)
    assert (costmap.resolution, costmap.origin_x, costmap.origin_y) == (0.1, -1.0, -2.0)
    expected = np.full((3, 4), FREE_SPACE, dtype=np.uint8)
    expected[1, 2] = LETHAL_OBSTACLE
    assert np.array_equal(costmap.data, expected)


@pytest.mark.parametrize(
    "grid",
    [None, "a map", SimpleNamespace(cells=np.zeros((3, 4), dtype=np.uint8), resolution=0.1,
                                    origin_x=0.0, origin_y=0.0),
     SimpleNamespace(cells=np.zeros((3, 4), dtype=bool), origin_x=0.0, origin_y=0.0)],
)
def test_anything_else_is_none(grid):
    assert Costmap2D.from_occupancy_cells(grid) is None
