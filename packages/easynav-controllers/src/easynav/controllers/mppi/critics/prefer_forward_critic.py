"""PreferForwardCritic: penalises driving backwards."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param


class PreferForwardCritic(Critic):
    """Σ_t max(−vx, 0)·dt: backwards travel, except within ``threshold_to_consider`` of the
    goal (where backing up a little to settle is fine)."""

    NAME = "PreferForwardCritic"
    DEFAULT_WEIGHT = 5.0
    PARAMETERS = (
        Param("threshold_to_consider", 0.5, "does not apply within this path length of the goal",
              "m", ge=0.0),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining < self.param("threshold_to_consider"):
            return None
        return np.maximum(-batch.vx, 0.0).sum(axis=1) * batch.dt
