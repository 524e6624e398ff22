"""GoalAngleCritic: near the goal, turn the rollouts to the goal's yaw."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic, wrap_angle
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param


class GoalAngleCritic(Critic):
    """Mean |yaw − goal yaw| (wrapped) along the rollout, within ``threshold_to_consider`` of
    the goal."""

    NAME = "GoalAngleCritic"
    DEFAULT_WEIGHT = 3.0
    PARAMETERS = (
        Param("threshold_to_consider", 0.5, "applies within this path length of the goal", "m",
              ge=0.0),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining > self.param("threshold_to_consider"):
            return None
        return np.abs(wrap_angle(batch.yaw - np.float32(batch.goal[2]))).mean(axis=1)
