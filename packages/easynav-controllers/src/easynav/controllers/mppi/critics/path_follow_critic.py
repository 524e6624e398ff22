"""PathFollowCritic: pull the rollouts' ends ahead along the path."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param


class PathFollowCritic(Critic):
    """Distance of each rollout's end to the path point ``offset_from_furthest`` beyond the
    furthest reached one; hands over to the goal critics within ``threshold_to_consider``."""

    NAME = "PathFollowCritic"
    DEFAULT_WEIGHT = 5.0
    PARAMETERS = (
        Param("offset_from_furthest", 5, "path points beyond the furthest reached", ge=0),
        Param("threshold_to_consider", 1.4, "does not apply within this path length of the goal",
              "m", ge=0.0),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining < self.param("threshold_to_consider"):
            return None
        if len(batch.path_xy) < 2:
            return None
        index = min(batch.furthest_reached_index() + self.param("offset_from_furthest"),
                    len(batch.path_xy) - 1)
        tx, ty = (np.float32(v) for v in batch.path_xy[index])
        return np.hypot(batch.x[:, -1] - tx, batch.y[:, -1] - ty)
