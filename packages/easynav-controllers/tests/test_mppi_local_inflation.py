"""MPPI on a map without inflation: the CostCritic inflates it near the robot.

LocalInflation against brute force and Nav2's formula; the CostCritic's scores on a binary map
equal its scores on the same map inflated beforehand; a costmap that has inflation is read as
it is; broken rollout points are left out; in closed loop towards a TurtleBot3 sandbox pillar
the controller drives on the binary map as on the map inflated.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt
from test_mppi import NAV2_SIZE, make_batch, make_controller, run_closed_loop

from easynav.controllers.mppi.collision_model import CollisionModel
from easynav.controllers.mppi.critics import CRITICS
from easynav.controllers.mppi.local_inflation import (
    LocalInflation,
    inflation_cost_table,
    local_inflation_reference,
    needs_local_inflation,
)
from easynav.core.nav_state import NavState
from easynav.core.robot import RobotLimits
from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, Costmap2D


def random_binary_costmap(seed=3, width=40, height=30, resolution=0.05):
    rng = np.random.default_rng(seed)
    costmap = Costmap2D.filled(width, height, resolution, -0.7, -0.4)
    costmap.data[rng.random((height, width)) < 0.03] = LETHAL_OBSTACLE
    return costmap


def nav2_inflated(costmap, inflation_radius, inscribed, k):
    """``costmap`` inflated over the whole map by Nav2's formula on scipy's exact distance
    transform (between cell centres), the cost rounded down."""
    distance = distance_transform_edt(costmap.data != LETHAL_OBSTACLE) * costmap.resolution
    costs = np.floor(252.0 * np.exp(-k * (distance - inscribed)))
    costs[distance > math.ceil(inflation_radius / costmap.resolution) * costmap.resolution] = 0
    costs[distance <= inscribed] = INSCRIBED_INFLATED_OBSTACLE
    costs[distance == 0.0] = LETHAL_OBSTACLE
    out = Costmap2D.filled(costmap.width, costmap.height, costmap.resolution, costmap.origin_x,
                           costmap.origin_y)
    out.data[:] = np.maximum(costmap.data, costs.astype(np.uint8))
    return out


def test_cost_table_is_nav2s_formula():
    table = inflation_cost_table(14, 0.05, 0.15, 3.0)
    assert table[0] == LETHAL_OBSTACLE
    assert table[4] == INSCRIBED_INFLATED_OBSTACLE  # 2 cells = 0.1 m: within the inscribed
    # 3 cells: 3 · 0.05 is a rounding above 0.15 in floating point, as in the costmap filter.
    assert table[9] == int(252 * math.exp(-3.0 * (3 * 0.05 - 0.15))) == 251
    assert table[10] == int(252 * math.exp(-3.0 * (math.sqrt(10) * 0.05 - 0.15)))
    assert table[196] == int(252 * math.exp(-3.0 * (0.7 - 0.15)))  # 14 cells: the radius
    assert table[197] == 0 and len(table) == 198  # beyond


@pytest.mark.parametrize("center", [(0.3, 0.4), (-0.6, -0.35), (1.2, 1.1)])
def test_window_costs_equal_brute_force(center):
    # The window round the centre (the last one reaches past the map's corner): every cell's
    # cost from the nearest lethal cell of the whole map, lethal cells outside the window
    # included; off the map no seeds.
    costmap = random_binary_costmap()
    local = LocalInflation(costmap, *center, 0.5, 0.3, 0.12, 3.0)
    height, width = local.costs.shape
    for row in range(height):
        for col in range(width):
            i, j = local.i0 + col, local.j0 + row
            expected = (local_inflation_reference(costmap, i, j, 0.3, 0.12, 3.0)
                        if 0 <= i < costmap.width and 0 <= j < costmap.height else None)
            if expected is None:  # off the map: only lethal cells within reach count
                continue
            assert local.costs[row, col] == expected, (i, j)


def test_window_equals_the_whole_map_inflated_by_nav2s_formula():
    costmap = random_binary_costmap(seed=5)
    inflated = nav2_inflated(costmap, 0.3, 0.12, 3.0)
    local = LocalInflation(costmap, 0.3, 0.35, 0.6, 0.3, 0.12, 3.0)
    ii, jj = np.meshgrid(np.arange(costmap.width), np.arange(costmap.height))
    x, y = costmap.cell_to_world(ii, jj)
    costs = local.at(x.astype(np.float32), y.astype(np.float32))
    inside = ((ii >= local.i0) & (ii < local.i0 + local.costs.shape[1])
              & (jj >= local.j0) & (jj < local.j0 + local.costs.shape[0]))
    assert inside.sum() > 300
    np.testing.assert_array_equal(costs[inside], inflated.data[inside])
    assert not costs[~inside].any()  # beyond the window: nothing


def test_needs_local_inflation_where_obstacles_have_none():
    costmap = random_binary_costmap()
    assert needs_local_inflation(costmap, 0.3, 0.35, 0.3, 0.3)
    assert not needs_local_inflation(nav2_inflated(costmap, 0.3, 0.12, 3.0), 0.3, 0.35, 0.3,
                                     0.3)
    empty = Costmap2D.filled(40, 30, 0.05, -0.7, -0.4)
    assert not needs_local_inflation(empty, 0.3, 0.35, 0.3, 0.3)  # no obstacle: nothing to do
    # Only the window (widened by the radius) is looked at: an inflated corner elsewhere does
    # not hide the bare obstacles near the robot.
    costmap.data[:5, :5] = 100
    assert needs_local_inflation(costmap, 0.6, 0.6, 0.2, 0.1)


def test_window_off_the_map_is_empty():
    costmap = random_binary_costmap()
    local = LocalInflation(costmap, 50.0, 50.0, 0.5, 0.3, 0.12, 3.0)
    assert local.costs.size == 0
    assert not local.at(np.array([50.0], np.float32), np.array([50.0], np.float32)).any()


def cost_critic_values(batch, radius, **params):
    values = {p.name: p.default for p in CRITICS["CostCritic"].declarations()}
    values.update({f"CostCritic.{k}": v for k, v in params.items()})
    batch.collision = CollisionModel(batch.costmap, batch.pose, 2.0, radius, 0.0, True)
    batch.costs[:] = 0.0
    CRITICS["CostCritic"](values).score(batch)
    return batch.costs.copy()


def test_cost_critic_scores_a_binary_map_as_the_map_inflated():
    # A wall along y = 0.5 and rollouts passing it at different distances: on the binary map
    # the critic grades them as on the map inflated beforehand with its inflation_radius and
    # cost_scaling_factor (inscribed radius: the robot's); the nearer, the dearer.
    costmap = Costmap2D.filled(80, 40, 0.05, -0.5, -1.0)
    costmap.data[30, :] = LETHAL_OBSTACLE  # y in [0.5, 0.55)
    wz = [[0.0] * 10] * 4
    vx = [[0.3] * 10] * 4
    batches = []
    for data in (costmap, nav2_inflated(costmap, 0.7, 0.15, 3.0)):
        batch = make_batch(vx, wz, costmap=data)
        for row, offset in enumerate((0.0, 0.1, 0.2, -0.3)):
            batch.y[row] += offset
        batches.append(batch)
    binary = cost_critic_values(batches[0], 0.15)
    inflated = cost_critic_values(batches[1], 0.15)
    np.testing.assert_allclose(binary, inflated, rtol=1e-6)
    assert binary[3] < binary[0] < binary[1] < binary[2]
    # inflation_radius 0: no graded term on a binary map (only the collision test).
    assert not cost_critic_values(batches[0], 0.15, inflation_radius=0.0).any()


def test_cost_critic_survives_non_finite_and_far_rollout_points():
    # An infinite or a far point (a broken rollout) must neither fail the cycle nor size the
    # window (a point 10 km away asked for a window of 149 GiB): the other rollouts are graded
    # as without it.
    costmap = Costmap2D.filled(80, 40, 0.05, -0.5, -1.0)
    costmap.data[30, :] = LETHAL_OBSTACLE
    batch = make_batch([[0.3] * 10] * 3, [[0.0] * 10] * 3, costmap=costmap)
    batch.y[1] += 0.1
    expected = cost_critic_values(batch, 0.15)
    for bad in (math.inf, -math.inf, 1.0e4):
        broken = make_batch([[0.3] * 10] * 3, [[0.0] * 10] * 3, costmap=costmap)
        broken.y[1] += 0.1
        broken.x[2, 4] = bad
        values = cost_critic_values(broken, 0.15)
        assert values[:2] == pytest.approx(expected[:2])
        assert values[2] >= 1e6  # off the map: a collision


def test_cost_critic_reads_an_inflated_costmap_as_it_is():
    # Its own inflation (a wider radius here) is not added to a costmap that has one.
    costmap = nav2_inflated(random_binary_costmap(seed=8), 0.2, 0.1, 3.0)
    batch = make_batch([[0.3] * 10] * 3, [[w] * 10 for w in (0.0, 0.3, -0.3)],
                       pose=(-0.5, 0.3, 0.0),
                       costmap=costmap)
    with_default = cost_critic_values(batch, 0.1)
    assert with_default == pytest.approx(cost_critic_values(batch, 0.1, inflation_radius=0.0))


#: A pillar of the TurtleBot3 sandbox as its map draws it (0.05 m cells, north up).
PILLAR = """
..####..
#######.
########
########
#######.
.######.
...###..
"""


def pillars_map(corners):
    """A binary costmap (0.05 m cells) with a :data:`PILLAR` whose north-west cell has its
    lower-left corner at each of ``corners``."""
    costmap = Costmap2D.filled(80, 60, 0.05, -1.5, -0.5)
    rows = PILLAR.strip().splitlines()
    for x, y in corners:
        i0, j0 = costmap.world_to_cell(x + 0.025, y + 0.025)
        for r, line in enumerate(rows):
            for c, mark in enumerate(line):
                if mark == "#":
                    costmap.data[j0 - r, i0 + c] = LETHAL_OBSTACLE
    return costmap


#: The matrix's MPPI parameters (params/costmap.mppi.params.yaml's).
MATRIX_MPPI = {
    "vx_std": 0.2, "wz_std": 0.4, "constant_noise_ratio": 0.5, "gamma": 0.015,
    "critics": ["ConstraintCritic", "CostCritic", "GoalCritic", "PathAlignCritic",
                "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic"],
    "CostCritic.cost_weight": 3.81, "CostCritic.collision_cost": 1e6,
    "CostCritic.near_goal_distance": 0.5, "PathAlignCritic.cost_weight": 10.0,
    "PathAlignCritic.offset_from_furthest": 20, "PathFollowCritic.cost_weight": 5.0,
    "GoalCritic.cost_weight": 5.0, "GoalCritic.threshold_to_consider": 1.4,
}

#: OMPL's path in the matrix run: east 0.65 m north of a row of pillars, south down the
#: passage past the corner of the pillar at (0.04, 1.08), west below it.
OMPL_PATH = np.array([
    [-0.44, 1.74], [-0.34, 1.73], [-0.24, 1.73], [-0.14, 1.72], [-0.04, 1.72], [0.06, 1.71],
    [0.15, 1.7], [0.25, 1.69], [0.34, 1.65], [0.42, 1.6], [0.5, 1.53], [0.56, 1.46],
    [0.6, 1.37], [0.62, 1.27], [0.62, 1.17], [0.62, 1.08], [0.62, 0.98], [0.61, 0.88],
    [0.6, 0.78], [0.56, 0.69], [0.5, 0.61], [0.42, 0.56], [0.32, 0.54], [0.22, 0.54],
    [0.12, 0.55], [0.03, 0.55], [-0.07, 0.56], [-0.17, 0.56], [-0.27, 0.56], [-0.37, 0.56]])


def test_drives_on_a_binary_map_as_on_the_map_inflated():
    # The matrix's TurtleBot3 sandbox run with the simple maps manager and OMPL: on the binary
    # map the path critics pulled the robot across the corner of the pillar the path turns
    # round, nothing graded held it off, and it rode the collision margin (with AMCL's 3 cm
    # error it touched the pillar). Inflated near the robot, the binary map gives the
    # controller the costs of the costmap stack's inflated map: over the first 6 s, towards
    # that corner, the same commands, pose for pose (without the inflation they differ from
    # the first cycle).
    corners = [(-1.2, 1.25), (-0.15, 1.2), (0.95, 1.2), (-1.2, 0.15), (-0.15, 0.15),
               (0.95, 0.1)]
    binary = pillars_map(corners)
    inflated = nav2_inflated(binary, 0.7, 0.15, 3.0)
    xy = OMPL_PATH
    yaw = np.arctan2(np.diff(xy[:, 1], append=xy[-1, 1]), np.diff(xy[:, 0], append=xy[-1, 0]))
    yaw[-1] = math.pi
    limits = RobotLimits(max_linear_vel=0.5, min_linear_vel=0.0, max_angular_vel=1.0,
                         max_linear_acc=0.5, max_linear_decel=1.0, max_angular_acc=1.0,
                         max_angular_decel=2.0)
    runs = []
    for costmap in (binary, inflated):
        controller = make_controller(dict(NAV2_SIZE, **MATRIX_MPPI), limits=limits, radius=0.15)
        nav_state = NavState()
        nav_state.set("map", costmap)
        runs.append(run_closed_loop(controller, np.column_stack((xy, yaw)), (-0.44, 1.74, 0.0),
                                    steps=120, nav_state=nav_state))
    (poses, commands, _), (inflated_poses, inflated_commands, _) = runs
    assert np.abs(commands).max() > 0.1  # it drives
    np.testing.assert_array_equal(commands, inflated_commands)
    np.testing.assert_array_equal(poses, inflated_poses)
