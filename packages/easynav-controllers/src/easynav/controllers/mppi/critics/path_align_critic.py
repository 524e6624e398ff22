"""PathAlignCritic: keep the rollouts on the path, point by point."""

from __future__ import annotations

import numpy as np

from easynav.controllers.mppi.critic import Critic, wrap_angle
from easynav.controllers.mppi.critics.cost_critic import rollout_costs
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param
from easynav.core.types import INSCRIBED_INFLATED_OBSTACLE


class PathAlignCritic(Critic):
    """Mean distance of every ``trajectory_point_step``-th rollout pose to the path point at the
    same arc length (rollout distance travelled ↔ path length from the robot's projection), up
    to the furthest reached path point (plus, with ``use_path_orientations``, the yaw error).

    Does not apply within ``threshold_to_consider`` of the goal, while fewer than
    ``offset_from_furthest`` path points are reached (too little path to align with), or when
    more than ``max_path_occupancy_ratio`` of those path points lie in lethal or inscribed cells
    (the path is blocked: the cost critic steers around the obstacle).
    """

    NAME = "PathAlignCritic"
    DEFAULT_WEIGHT = 10.0
    PARAMETERS = (
        Param("offset_from_furthest", 20, "path points that must be reached to apply", ge=0),
        Param("trajectory_point_step", 4, "score every n-th rollout pose", ge=1),
        Param("threshold_to_consider", 0.5, "does not apply within this path length of the goal",
              "m", ge=0.0),
        Param("max_path_occupancy_ratio", 0.07, "blocked-path fraction above which to skip",
              ge=0.0, le=1.0),
        Param("use_path_orientations", False, "add the yaw error to the path pose's yaw"),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining < self.param("threshold_to_consider"):
            return None
        furthest = batch.furthest_reached_index()
        if furthest < self.param("offset_from_furthest") or furthest < 1:
            return None
        path = batch.path_xy[: furthest + 1].astype(np.float32)
        if batch.costmap is not None:
            blocked = rollout_costs(batch.costmap, path[:, 0], path[:, 1])
            blocked = (blocked >= INSCRIBED_INFLATED_OBSTACLE) & (blocked != 255)
            if blocked.mean() > self.param("max_path_occupancy_ratio"):
                return None
        step = self.param("trajectory_point_step")
        x = batch.x[:, step - 1 :: step]
        y = batch.y[:, step - 1 :: step]
        # Distance travelled along each rollout up to each scored pose.
        travelled = np.abs(batch.vx).cumsum(axis=1, dtype=np.float32)[:, step - 1 :: step]
        travelled *= np.float32(batch.dt)
        path_s = batch.path_s[: furthest + 1].astype(np.float32)
        index = np.searchsorted(path_s, travelled)
        valid = index <= furthest
        np.clip(index, 1, furthest, out=index)
        # The path point at the same arc length, interpolated on its segment.
        s0 = path_s[index - 1]
        length = path_s[index] - s0
        fraction = np.clip((travelled - s0) / np.where(length > 0, length, 1), 0, 1)
        px = path[index - 1, 0] + fraction * (path[index, 0] - path[index - 1, 0])
        py = path[index - 1, 1] + fraction * (path[index, 1] - path[index - 1, 1])
        d = np.hypot(x - px, y - py)
        if self.param("use_path_orientations"):
            path_yaw = batch.path_yaw[: furthest + 1].astype(np.float32)
            d += np.abs(wrap_angle(batch.yaw[:, step - 1 :: step] - path_yaw[index]))
        count = valid.sum(axis=1)
        total = np.where(valid, d, 0.0).sum(axis=1, dtype=np.float32)
        return np.where(count > 0, total / np.maximum(count, 1), 0.0).astype(np.float32)
