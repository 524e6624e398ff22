"""MPPI's local inflation (easynav-controllers) gives the costs of the costmap stack's inflation
(easynav-maps) for the same radius, scaling factor and inscribed radius: a SimpleMap under MPPI
is graded as the costmap stack grades its map."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.controllers.mppi.local_inflation import LocalInflation
from easynav.core.types import LETHAL_OBSTACLE, Costmap2D
from easynav.maps.inflation import inflate


@pytest.mark.parametrize(("radius", "inscribed", "scaling"), [(0.7, 0.15, 3.0), (0.3, 0.2, 10.0)])
def test_local_inflation_equals_the_inflation_filter(radius, inscribed, scaling):
    rng = np.random.default_rng(11)
    costmap = Costmap2D.filled(90, 70, 0.05, -2.0, -1.5)
    costmap.data[rng.random((70, 90)) < 0.01] = LETHAL_OBSTACLE
    costmap.data[35, 10:60] = LETHAL_OBSTACLE  # a wall
    filtered = inflate(costmap.data, costmap.resolution, radius, inscribed, scaling)
    local = LocalInflation(costmap, 0.2, 0.3, 1.2, radius, inscribed, scaling)
    height, width = local.costs.shape
    window = filtered[local.j0:local.j0 + height, local.i0:local.i0 + width]
    assert window.shape == local.costs.shape and (window > 0).mean() > 0.3
    np.testing.assert_array_equal(local.costs, window)
