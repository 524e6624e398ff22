"""ConstraintCritic: penalises speeds outside the limits in force."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.mppi_batch import MppiBatch


class ConstraintCritic(Critic):
    """Σ_t (max(vx − max_v, 0) + max(min_v − vx, 0) + max(|wz| − max_w, 0))·dt per sample.

    The optimiser already clamps sampled controls to the limits, so this only bites when the
    limits in force drop below the warm-started sequence (a slow-down mitigation) before the
    clamp, or for a custom batch; it keeps Nav2's weighting of that case.
    """

    NAME = "ConstraintCritic"
    DEFAULT_WEIGHT = 4.0

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        limits = batch.limits
        min_v = min(limits.min_linear_vel, 0.0)
        if (batch.vx.max() <= limits.max_linear_vel and batch.vx.min() >= min_v
                and np.abs(batch.wz).max() <= limits.max_angular_vel):
            return None  # the usual case: the optimiser clamped the samples already
        over = np.maximum(batch.vx - limits.max_linear_vel, 0.0)
        over += np.maximum(min_v - batch.vx, 0.0)
        over += np.maximum(np.abs(batch.wz) - limits.max_angular_vel, 0.0)
        return over.sum(axis=1) * batch.dt
