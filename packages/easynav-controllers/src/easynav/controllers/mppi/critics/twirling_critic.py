"""TwirlingCritic: penalises needless turning."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param


class TwirlingCritic(Critic):
    """Mean |wz| along the sequence, except within ``threshold_to_consider`` of the goal (the
    final turn to the goal yaw is wanted)."""

    NAME = "TwirlingCritic"
    DEFAULT_WEIGHT = 10.0
    PARAMETERS = (
        Param("threshold_to_consider", 0.5, "does not apply within this path length of the goal",
              "m", ge=0.0),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining < self.param("threshold_to_consider"):
            return None
        return np.abs(batch.wz).mean(axis=1)
