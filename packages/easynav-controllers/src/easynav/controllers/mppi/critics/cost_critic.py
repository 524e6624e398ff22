"""CostCritic: the costmap's cost along the rollouts; collisions are prohibitive."""

from __future__ import annotations

import math

import numpy as np

from easynav.controllers.mppi.collision_model import CollisionModel, rollout_costs
from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.local_inflation import LocalInflation, needs_local_inflation
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param
from easynav.core.types import LETHAL_OBSTACLE

__all__ = ["CostCritic", "rollout_costs"]


class CostCritic(Critic):
    """Costs of the cells under every ``trajectory_point_step``-th rollout pose.

    A rollout collides (:class:`CollisionModel`) when one of those poses is on an inscribed or
    lethal cell (or unknown space with ``consider_unknown_lethal``, or off the map), or nearer
    than ``robot_geometry.radius + collision_margin`` to an obstacle cell: ``collision_cost``
    is added, unweighted.
    Otherwise ``(cost_weight · Σ (cost / 254) / points)^cost_power``, except within
    ``near_goal_distance`` of the goal (a goal near a wall stays reachable). No costmap in
    NavState: no term.

    Obstacles without inflation (no cell between free and inscribed round them: a SimpleMap or
    a GridMap read as a costmap, a costmap with no inflation filter) are inflated near the
    robot, for this term only, with ``inflation_radius`` and ``cost_scaling_factor``
    (:class:`LocalInflation`; the inscribed radius is ``robot_geometry.radius``): without the
    graded costs the path critics pull the robot across the corners of obstacles up to the
    collision margin.
    """

    NAME = "CostCritic"
    DEFAULT_WEIGHT = 3.81
    PARAMETERS = (
        Param("collision_cost", 1000000.0, "added to a colliding rollout (unweighted)", ge=0.0),
        Param("near_goal_distance", 0.5, "no repulsive term within this path length of the goal",
              "m", ge=0.0),
        Param("trajectory_point_step", 2, "score every n-th rollout pose", ge=1),
        Param("consider_unknown_lethal", True, "unknown cells (255) count as collisions"),
        Param("collision_margin", 0.05,
              "clearance kept between the robot's disc (robot_geometry.radius) and obstacle "
              "cells, for the localisation and tracking errors (beyond Nav2)", "m", ge=0.0),
        Param("inflation_radius", 0.7,
              "for a costmap without inflation: the radius of the inflation computed near the "
              "robot (0: none; beyond Nav2)", "m", ge=0.0),
        Param("cost_scaling_factor", 3.0,
              "for a costmap without inflation: the decay rate of that inflation's cost "
              "(beyond Nav2)", "1/m", ge=0.0),
    )

    def score(self, batch: MppiBatch) -> None:
        if not self.param("enabled") or batch.costmap is None:
            return
        step = self.param("trajectory_point_step")
        x, y = batch.x[:, ::step], batch.y[:, ::step]
        costs = rollout_costs(batch.costmap, x, y)
        collision = batch.collision or CollisionModel(
            batch.costmap, batch.pose, 0.0, 0.0, 0.0, self.param("consider_unknown_lethal"))
        lethal = collision.colliding(x, y, costs)
        collided = lethal.any(axis=1)
        batch.costs += np.float32(self.param("collision_cost")) * collided
        if batch.remaining < self.param("near_goal_distance"):
            return
        inflation = self._local_inflation(batch, x, y, collision.radius)
        if inflation is not None:
            costs = np.maximum(costs, inflation.at(x, y))
        graded = np.where(lethal, 0, costs).sum(axis=1, dtype=np.float32)
        # Costs normalised to [0, 1] (÷ 254, as Nav2) so the weight is comparable with the
        # other critics' (metres, radians).
        term = self.param("cost_weight") * graded / np.float32(costs.shape[1] * LETHAL_OBSTACLE)
        power = self.param("cost_power")
        batch.costs += term if power == 1 else term**power

    def _local_inflation(self, batch: MppiBatch, x: np.ndarray, y: np.ndarray,
                         radius: float) -> LocalInflation | None:
        """The inflation of the window the points ``(x, y)`` span, when its obstacles have
        none (and ``inflation_radius`` is set); else None. Non-finite points are left out
        (they collide anyway)."""
        inflation_radius = self.param("inflation_radius")
        x0, y0 = batch.pose[0], batch.pose[1]
        if inflation_radius <= 0.0 or not (math.isfinite(x0) and math.isfinite(y0)):
            return None
        finite = np.isfinite(x) & np.isfinite(y)
        if not finite.any():
            return None
        costmap = batch.costmap
        half_size = float(max(np.abs(x[finite] - np.float32(x0)).max(),
                              np.abs(y[finite] - np.float32(y0)).max())) + costmap.resolution
        if not needs_local_inflation(costmap, x0, y0, half_size, inflation_radius):
            return None
        return LocalInflation(costmap, x0, y0, half_size, inflation_radius, radius,
                              self.param("cost_scaling_factor"))

    def compute(self, batch: MppiBatch) -> np.ndarray | None:  # pragma: no cover - score()
        """Not used: this critic adds its two terms (collision, graded cost) in :meth:`score`."""
        return None
