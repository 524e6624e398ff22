"""GoalCritic: near the goal, pull every rollout toward it."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param


class GoalCritic(Critic):
    """Mean distance of the rollout's poses to the goal, once the robot is within
    ``threshold_to_consider`` of it (the path critics hand over to it there)."""

    NAME = "GoalCritic"
    DEFAULT_WEIGHT = 5.0
    PARAMETERS = (
        Param("threshold_to_consider", 1.4, "applies within this path length of the goal", "m",
              ge=0.0),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining > self.param("threshold_to_consider"):
            return None
        gx, gy, _ = batch.goal
        return np.hypot(batch.x - gx, batch.y - gy).mean(axis=1)
