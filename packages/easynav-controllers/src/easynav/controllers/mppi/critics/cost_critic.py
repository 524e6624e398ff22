"""CostCritic: the costmap's cost along the rollouts; collisions are prohibitive."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param
from easynav.core.types import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)


def rollout_costs(costmap: Costmap2D, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Costmap values (uint8) at the points ``(x, y)``; off the map: NO_INFORMATION."""
    ix = np.floor((x - np.float32(costmap.origin_x)) * np.float32(1.0 / costmap.resolution))
    iy = np.floor((y - np.float32(costmap.origin_y)) * np.float32(1.0 / costmap.resolution))
    ix = ix.astype(np.int32)
    iy = iy.astype(np.int32)
    inside = (ix >= 0) & (ix < costmap.width) & (iy >= 0) & (iy < costmap.height)
    np.clip(ix, 0, costmap.width - 1, out=ix)
    np.clip(iy, 0, costmap.height - 1, out=iy)
    costs = costmap.data[iy, ix]
    costs[~inside] = NO_INFORMATION
    return costs


class CostCritic(Critic):
    """Costs of the cells under every ``trajectory_point_step``-th rollout pose.

    A rollout through an inscribed or lethal cell (or unknown space with
    ``consider_unknown_lethal``, or off the map) collides: ``collision_cost`` is added, unweighted.
    Otherwise ``(cost_weight · Σ (cost / 254) / points)^cost_power``, except within
    ``near_goal_distance`` of the goal (a goal near a wall stays reachable). No costmap in
    NavState: no term.
    """

    NAME = "CostCritic"
    DEFAULT_WEIGHT = 3.81
    PARAMETERS = (
        Param("collision_cost", 1000000.0, "added to a colliding rollout (unweighted)", ge=0.0),
        Param("near_goal_distance", 0.5, "no repulsive term within this distance of the goal",
              "m", ge=0.0),
        Param("trajectory_point_step", 2, "score every n-th rollout pose", ge=1),
        Param("consider_unknown_lethal", True, "unknown cells (255) count as collisions"),
    )

    def score(self, batch: MppiBatch) -> None:
        if not self.param("enabled") or batch.costmap is None:
            return
        step = self.param("trajectory_point_step")
        costs = rollout_costs(batch.costmap, batch.x[:, ::step], batch.y[:, ::step])
        lethal = costs >= INSCRIBED_INFLATED_OBSTACLE
        if not self.param("consider_unknown_lethal"):
            lethal &= costs != NO_INFORMATION
        collided = lethal.any(axis=1)
        batch.costs += np.float32(self.param("collision_cost")) * collided
        if batch.path_is_final and batch.goal_dist < self.param("near_goal_distance"):
            return
        graded = np.where(lethal, 0, costs).sum(axis=1, dtype=np.float32)
        # Costs normalised to [0, 1] (÷ 254, as Nav2) so the weight is comparable with the
        # other critics' (metres, radians).
        term = self.param("cost_weight") * graded / np.float32(costs.shape[1] * LETHAL_OBSTACLE)
        power = self.param("cost_power")
        batch.costs += term if power == 1 else term**power

    def compute(self, batch: MppiBatch) -> np.ndarray | None:  # pragma: no cover - score()
        """Not used: this critic adds its two terms (collision, graded cost) in :meth:`score`."""
        return None
