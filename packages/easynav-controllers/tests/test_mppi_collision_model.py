"""MPPI's collision model without ROS: the clearance field against brute-force distances, the
robot's disc and margin, and a path along a pillar's face in closed loop."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_mppi import NAV2_SIZE, make_controller, run_closed_loop

from easynav.controllers.mppi.collision_model import (
    INSIDE_MARGIN_SLACK,
    ClearanceField,
    CollisionModel,
    clearance_reference,
)
from easynav.core.nav_state import NavState
from easynav.core.robot import RobotGeometry
from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, Costmap2D

RES = 0.05
#: Bilinear interpolation of a 1-Lipschitz distance: at most the mean distance from a point to
#: the corners of its cell, which is largest (half a diagonal) at the cell's centre.
INTERPOLATION_BOUND = math.sqrt(2.0) / 2.0 * RES + 1e-6


def scattered_costmap(seed=3) -> Costmap2D:
    rng = np.random.default_rng(seed)
    costmap = Costmap2D.filled(60, 60, RES, -1.5, -1.5)
    costmap.data[rng.random((60, 60)) < 0.02] = LETHAL_OBSTACLE
    costmap.data[20:25, 30:40] = 255  # unknown block
    return costmap


@pytest.mark.parametrize("unknown_is_obstacle", [True, False])
def test_clearance_field_at_cell_centres_is_the_exact_distance(unknown_is_obstacle):
    costmap = scattered_costmap()
    cap = 0.3
    field = ClearanceField(costmap, 0.0, 0.0, 1.0, cap, unknown_is_obstacle)
    height, width = field.distance.shape
    for j in range(0, height, 3):
        for i in range(0, width, 3):
            x = costmap.origin_x + (field.i0 + i + 0.5) * RES
            y = costmap.origin_y + (field.j0 + j + 0.5) * RES
            expected = min(clearance_reference(costmap, x, y, unknown_is_obstacle), cap)
            assert field.distance[j, i] == pytest.approx(expected, abs=1e-6)


def test_clearance_field_between_centres_within_the_interpolation_bound():
    costmap = scattered_costmap()
    field = ClearanceField(costmap, 0.0, 0.0, 1.0, 0.3, True)
    rng = np.random.default_rng(4)
    points = rng.uniform(-0.9, 0.9, (2000, 2)).astype(np.float32)
    values = field.at(points[:, 0], points[:, 1])
    for (x, y), value in zip(points, values, strict=True):
        expected = min(clearance_reference(costmap, float(x), float(y), True), 0.3)
        assert abs(value - expected) <= INTERPOLATION_BOUND
    # below() agrees with at() everywhere.
    threshold = 0.2
    assert np.array_equal(field.below(points[:, 0], points[:, 1], threshold), values < threshold)


def test_clearance_field_is_exact_along_a_straight_wall_and_off_the_map_is_unknown():
    costmap = Costmap2D.filled(40, 40, RES, 0.0, 0.0)
    costmap.data[:, 30:] = LETHAL_OBSTACLE  # wall face at x = 1.5
    field = ClearanceField(costmap, 1.2, 1.0, 0.5, 0.4, False)
    xs = np.float32([1.2, 1.23, 1.31, 1.37])
    assert field.at(xs, np.full(4, 1.01, np.float32)) == pytest.approx(1.5 - xs, abs=1e-5)
    # The map ends at y = 2.0: beyond it is unknown space, an obstacle when asked.
    near_edge = ClearanceField(costmap, 0.5, 1.9, 0.3, 0.4, True)
    assert near_edge.at(np.float32([0.5]), np.float32([1.9]))[0] == pytest.approx(0.1, abs=1e-5)


def wall_costmap() -> Costmap2D:
    """Lethal cells from x = 1.0 on; no inflation (only the disc test can keep the robot off)."""
    costmap = Costmap2D.filled(60, 40, RES, -1.0, -1.0)
    costmap.data[:, 40:] = LETHAL_OBSTACLE
    return costmap


def test_the_disc_and_margin_against_a_wall():
    costmap = wall_costmap()
    model = CollisionModel(costmap, (0.0, 0.0, 0.0), 1.0, 0.15, 0.05, True)
    assert model.threshold == pytest.approx(0.2)
    xs = np.float32([[0.70, 0.79], [0.70, 0.82]])  # 0.21 m and 0.18 m from the wall
    assert model.colliding(xs, np.zeros_like(xs)).tolist() == [[False, False], [False, True]]
    # Without radius or margin only the cell under the centre counts (as Nav2's CostCritic).
    bare = CollisionModel(costmap, (0.0, 0.0, 0.0), 1.0, 0.0, 0.0, True)
    assert not bare.colliding(np.float32([0.99]), np.float32([0.0])).any()
    assert bare.colliding(np.float32([1.01]), np.float32([0.0])).all()
    # Inscribed cells still collide wherever they are.
    costmap.data[20, 5] = INSCRIBED_INFLATED_OBSTACLE
    x, y = costmap.cell_to_world(5, 20)
    assert model.colliding(np.float32([x]), np.float32([y])).all()


def test_a_robot_inside_the_margin_may_move_along_or_away_not_closer():
    costmap = wall_costmap()
    # 0.18 m from the wall: inside radius + margin (0.2 m).
    model = CollisionModel(costmap, (0.82, 0.0, 0.0), 1.0, 0.15, 0.05, True)
    assert model.threshold == pytest.approx(0.18 - INSIDE_MARGIN_SLACK, abs=1e-4)
    along = np.float32([[0.82, 0.82, 0.82]]), np.float32([[0.0, 0.2, 0.4]])
    away = np.float32([[0.82, 0.7, 0.5]]), np.zeros((1, 3), np.float32)
    closer = np.float32([[0.82, 0.84, 0.86]]), np.zeros((1, 3), np.float32)
    assert not model.colliding(*along).any()
    assert not model.colliding(*away).any()
    assert model.colliding(*closer)[0].tolist() == [False, True, True]
    # The hold carries over and moves only inwards while the robot stays inside the margin:
    # it is not let a little nearer each cycle.
    assert CollisionModel(costmap, (0.82, 0.0, 0.0), 1.0, 0.15, 0.05, True,
                          held=0.15).threshold == pytest.approx(0.15)
    later = CollisionModel(costmap, (0.84, 0.0, 0.0), 1.0, 0.15, 0.05, True, held=model.held)
    assert later.threshold == pytest.approx(0.16 - INSIDE_MARGIN_SLACK, abs=1e-4)
    # Moving as near as the hold allows does not move the hold: no creeping in, a hair's
    # breadth a cycle (each cycle the robot goes to the hold, 0.17 m, and a little beyond it
    # by the field's rounding).
    hold = model.held
    for _ in range(20):
        nearest = 0.82 + (0.18 - hold) - 0.001  # 1 mm short of the hold
        cycle = CollisionModel(costmap, (nearest, 0.0, 0.0), 1.0, 0.15, 0.05, True, held=hold)
        assert cycle.held == pytest.approx(model.held)
        hold = cycle.held
    # Out of the margin again: released.
    assert CollisionModel(costmap, (0.5, 0.0, 0.0), 1.0, 0.15, 0.05, True,
                          held=0.15).held is None


def test_a_robot_over_an_obstacle_may_only_get_out():
    costmap = wall_costmap()
    # 0.10 m from the wall with a 0.15 m radius: the estimate overlaps it. Held at the radius,
    # not at its depth, and only rollouts that get out are clear: away, or turning on the
    # spot, not along the wall nor nearer (as each gains less than ESCAPE_GAIN per metre).
    model = CollisionModel(costmap, (0.90, 0.0, 0.0), 1.0, 0.15, 0.05, True)
    assert model.escaping and model.threshold == pytest.approx(0.15)
    rollouts = {
        "away": ([0.85, 0.80, 0.70], [0.0, 0.0, 0.0]),
        "away at 45 degrees": ([0.86, 0.82, 0.78], [0.04, 0.08, 0.12]),
        "turning on the spot": ([0.90, 0.90, 0.90], [0.0, 0.0, 0.0]),
        "along": ([0.90, 0.90, 0.90], [0.05, 0.10, 0.15]),
        "nearly along": ([0.895, 0.89, 0.885], [0.05, 0.10, 0.15]),
        "nearer": ([0.91, 0.92, 0.93], [0.0, 0.0, 0.0]),
    }
    expected = {"away": False, "away at 45 degrees": False, "turning on the spot": False,
                "along": True, "nearly along": True, "nearer": True}
    for name, (xs, ys) in rollouts.items():
        x, y = np.float32([xs]), np.float32([ys])
        assert model.colliding(x, y).any() == expected[name], name  # the critics' field
        assert model.rollout_collides(x[0], y[0]) == expected[name], name  # the guard
    # Found nearer (a hit drawn nearer): still only out, from there.
    nearer = CollisionModel(costmap, (0.92, 0.0, 0.0), 1.0, 0.15, 0.05, True, held=model.held)
    assert nearer.escaping and nearer.threshold == pytest.approx(0.15)
    # Just outside the radius (0.155 m): the hold keeps its slack, below the radius; moved
    # into that slack, over the obstacle, it may only get out again.
    near = CollisionModel(costmap, (0.845, 0.0, 0.0), 1.0, 0.15, 0.05, True)
    assert not near.escaping
    assert near.threshold == pytest.approx(0.155 - INSIDE_MARGIN_SLACK, abs=1e-4)
    slid = CollisionModel(costmap, (0.853, 0.0, 0.0), 1.0, 0.15, 0.05, True, held=near.held)
    assert slid.escaping and slid.threshold == pytest.approx(0.15)
    along = np.float32([[0.853, 0.853]]), np.float32([[0.01, 0.02]])
    assert slid.colliding(*along).any() and slid.rollout_collides(along[0][0], along[1][0])
    # Out of the margin: released.
    out = CollisionModel(costmap, (0.5, 0.0, 0.0), 1.0, 0.15, 0.05, True, held=model.held)
    assert not out.escaping and out.held is None


def test_a_tight_path_lowers_the_threshold_never_below_the_radius():
    costmap = wall_costmap()
    def path_at(x):
        return np.column_stack((np.full(20, x), np.linspace(-0.5, 0.5, 20)))
    assert CollisionModel(costmap, (0.5, 0.0, 0.0), 1.0, 0.15, 0.05, True,
                          path_at(0.5)).threshold == pytest.approx(0.2)
    assert CollisionModel(costmap, (0.5, 0.0, 0.0), 1.0, 0.15, 0.05, True,
                          path_at(0.83)).threshold == pytest.approx(0.16, abs=1e-4)
    assert CollisionModel(costmap, (0.5, 0.0, 0.0), 1.0, 0.15, 0.05, True,
                          path_at(0.9)).threshold == pytest.approx(0.15)
    # Path points beyond the rollouts' reach do not count.
    assert CollisionModel(costmap, (0.5, 0.0, 0.0), 0.2, 0.15, 0.05, True,
                          path_at(0.9)).threshold == pytest.approx(0.2)


def pillar_costmap(inscribed=0.15, k=3.0):
    """A 0.3 m square pillar (lethal cells) at x 1.5..1.8, y 0.15..0.45, inflated as the
    costmap stack does (cell-centre distances: inscribed within ``inscribed``)."""
    costmap = Costmap2D.filled(80, 60, RES, -0.5, -1.0)
    costmap.data[23:29, 40:46] = LETHAL_OBSTACLE
    jj, ii = np.mgrid[0:60, 0:80]
    lethal = np.argwhere(costmap.data == LETHAL_OBSTACLE)
    distance = np.min(np.hypot(jj[..., None] - lethal[:, 0], ii[..., None] - lethal[:, 1]),
                      axis=2) * RES
    graded = np.floor(252 * np.exp(-k * (distance - inscribed))).clip(0, 252)
    data = np.where(distance <= inscribed, INSCRIBED_INFLATED_OBSTACLE, graded)
    data[distance == 0.0] = LETHAL_OBSTACLE
    costmap.data[:] = data.astype(np.uint8)
    return costmap


def path_round_a_corner(distance):
    """Along the pillar's south face, round its south-east corner (1.8, 0.15) and up its east
    face, ``distance`` from the pillar all along."""
    along = np.column_stack((np.arange(0.0, 1.8, 0.05), np.full(36, 0.15 - distance)))
    angles = np.linspace(-math.pi / 2, 0.0, 12)[1:]
    corner = np.column_stack((1.8 + distance * np.cos(angles), 0.15 + distance * np.sin(angles)))
    up = np.column_stack((np.full(14, 1.8 + distance), 0.15 + np.arange(1, 15) * 0.05))
    xy = np.vstack((along, corner, up))
    yaw = np.arctan2(np.diff(xy[:, 1], append=xy[-1, 1]), np.diff(xy[:, 0], append=xy[-1, 0]))
    yaw[-1] = math.pi / 2
    return np.column_stack((xy, yaw))


def test_round_a_pillar_corner_the_robot_keeps_the_path_clearance():
    # The path keeps 5 cm between the robot (radius 0.15 m) and the pillar. With the cell test
    # alone MPPI cut the corner through cells that are not inscribed (their centres are more
    # than 0.15 m from the pillar's cell centres) and the robot overlapped the pillar by 1.6 to
    # 4.3 cm (seeds 7 to 10). The disc test holds it to the path's clearance less the slack.
    costmap = pillar_costmap()
    nav_state = NavState()
    nav_state.set("map", costmap)
    controller = make_controller(NAV2_SIZE)
    controller.context.robot_geometry = lambda: RobotGeometry(radius=0.15, inscribed_radius=0.15)
    path = path_round_a_corner(0.2)
    poses, _commands, states = run_closed_loop(controller, path, (0.0, path[0, 1], 0.0),
                                               steps=1500, nav_state=nav_state)
    assert states[-1] == "arrived"
    clearance = min(clearance_reference(costmap, x, y, True) for x, y, _ in poses) - 0.15
    assert clearance >= 0.05 - INSIDE_MARGIN_SLACK - 1e-3  # 1 mm: the harness's integration
