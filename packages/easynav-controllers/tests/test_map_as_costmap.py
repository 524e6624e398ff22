"""MapAsCostmap: the NavState map as a Costmap2D for the controllers' obstacle terms."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from easynav.controllers.map_as_costmap import MapAsCostmap
from easynav.core.types import FREE_SPACE, LETHAL_OBSTACLE, NO_INFORMATION, Costmap2D


@dataclass
class OccupancyCells:
    """The shape of the simple maps manager's SimpleMap, as the controllers read it."""

    cells: np.ndarray
    resolution: float = 0.1
    origin_x: float = -1.0
    origin_y: float = -2.0


def test_a_costmap_is_used_as_it_is():
    costmap = Costmap2D.filled(4, 3, 0.05)
    assert MapAsCostmap()(costmap) is costmap


def test_an_occupancy_grid_becomes_lethal_and_free_cells_once_per_map():
    cells = np.zeros((3, 4), dtype=bool)
    cells[1, 2] = True
    grid = OccupancyCells(cells)
    as_costmap = MapAsCostmap()
    costmap = as_costmap(grid)
    assert (costmap.resolution, costmap.origin_x, costmap.origin_y) == (0.1, -1.0, -2.0)
    assert costmap.data[1, 2] == LETHAL_OBSTACLE
    assert (costmap.data[cells == 0] == FREE_SPACE).all()
    assert costmap.cost_at(-1.0 + 0.25, -2.0 + 0.15) == LETHAL_OBSTACLE  # cell (2, 1)
    assert as_costmap(grid) is costmap  # the same map: no new conversion
    other = OccupancyCells(np.ones((3, 4), dtype=bool))
    assert (as_costmap(other).data == LETHAL_OBSTACLE).all()


@pytest.mark.parametrize(
    "value",
    [None, "a map", OccupancyCells(np.zeros((3, 4), dtype=np.uint8)),
     OccupancyCells(np.zeros(4, dtype=bool))],
)
def test_anything_else_gives_no_obstacle_terms(value):
    assert MapAsCostmap()(value) is None


def test_the_simple_maps_managers_map_converts():
    simple_map = pytest.importorskip("easynav.maps.simple_map")
    grid = simple_map.SimpleMap(5, 4, 0.2, 1.0, 2.0)
    grid.mark_occupied(1.3, 2.5)  # cell (1, 2)
    costmap = MapAsCostmap()(grid)
    assert costmap.data.shape == (4, 5) and costmap.data[2, 1] == LETHAL_OBSTACLE
    assert int((costmap.data == LETHAL_OBSTACLE).sum()) == 1


def test_the_gridmap_managers_map_converts_untraversable_cells_to_lethal_ones():
    # The GridMap stack: MPPI, RPP and SeReST keep off what the elevation map says cannot be
    # driven (on the campus with raised buildings, MPPI without obstacle terms cut a corner
    # into one).
    gridmap = pytest.importorskip("easynav.maps.gridmap")
    elevation = np.zeros((6, 8))
    elevation[2:4, 5:7] = 2.0  # a block 2 m high
    elevation[0, 0] = np.nan  # unknown height
    grid = gridmap.GridMap.from_elevation(elevation, 0.2, -1.0, 3.0, np.radians(30.0))
    as_costmap = MapAsCostmap()
    costmap = as_costmap(grid)
    assert (costmap.resolution, costmap.origin_x, costmap.origin_y) == (0.2, -1.0, 3.0)
    untraversable = grid.layer("traversability") <= 0.0
    assert untraversable[2, 4] and untraversable[1, 5]  # the ring round the block is steep
    assert (costmap.data[untraversable] == LETHAL_OBSTACLE).all()
    unknown = ~np.isfinite(grid.layer("traversability"))
    assert unknown[0, 0] and (costmap.data[unknown] == NO_INFORMATION).all()
    assert (costmap.data[~untraversable & ~unknown] == FREE_SPACE).all()
    assert costmap.data[3, 1] == FREE_SPACE
    assert as_costmap(grid) is costmap  # the same map: no new conversion


@dataclass
class Layers:
    layers: object
    resolution: float = 0.1
    origin_x: float = 0.0
    origin_y: float = 0.0


@pytest.mark.parametrize(
    "value",
    [Layers({}), Layers({"traversability": np.ones(4)}), Layers([np.ones((2, 2))]),
     Layers({"traversability": np.ones((2, 2))}, resolution="fine")],
)
def test_layers_without_a_2d_traversability_give_no_obstacle_terms(value):
    assert MapAsCostmap()(value) is None
