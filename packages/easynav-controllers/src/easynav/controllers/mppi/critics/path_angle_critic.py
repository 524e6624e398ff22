"""PathAngleCritic: point the rollouts at the path ahead when the robot faces away from it."""

from __future__ import annotations

import math

import numpy as np

from easynav.controllers.mppi.critic import Critic, wrap_angle
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param

FORWARD_PREFERENCE = 0
NO_DIRECTIONAL_PREFERENCE = 1


class PathAngleCritic(Critic):
    """Mean angle between each rollout pose's heading and the direction to the path point
    ``offset_from_furthest`` beyond the furthest reached one, applied only while the robot's own
    angle to that point exceeds ``max_angle_to_furthest``. ``mode`` 0: forward preference; 1: no
    directional preference (driving backwards toward it is as good)."""

    NAME = "PathAngleCritic"
    DEFAULT_WEIGHT = 2.2
    PARAMETERS = (
        Param("offset_from_furthest", 4, "path points beyond the furthest reached", ge=0),
        Param("threshold_to_consider", 0.5, "does not apply within this path length of the goal",
              "m", ge=0.0),
        Param("max_angle_to_furthest", 0.785, "applies when the robot's angle exceeds it", "rad",
              ge=0.0),
        Param("mode", 0, "0: forward preference, 1: no directional preference",
              choices=(FORWARD_PREFERENCE, NO_DIRECTIONAL_PREFERENCE)),
    )

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        if batch.remaining < self.param("threshold_to_consider"):
            return None
        if len(batch.path_xy) < 2:
            return None
        index = min(batch.furthest_reached_index() + self.param("offset_from_furthest"),
                    len(batch.path_xy) - 1)
        tx, ty = (float(v) for v in batch.path_xy[index])
        x0, y0, yaw0 = batch.pose
        mode = self.param("mode")
        robot_angle = abs(math.remainder(math.atan2(ty - y0, tx - x0) - yaw0, 2.0 * math.pi))
        if mode == NO_DIRECTIONAL_PREFERENCE:
            robot_angle = min(robot_angle, math.pi - robot_angle)
        if robot_angle < self.param("max_angle_to_furthest"):
            return None
        angle = np.abs(wrap_angle(
            np.arctan2(np.float32(ty) - batch.y, np.float32(tx) - batch.x) - batch.yaw
        ))
        if mode == NO_DIRECTIONAL_PREFERENCE:
            angle = np.minimum(angle, np.float32(math.pi) - angle)
        return angle.mean(axis=1)
