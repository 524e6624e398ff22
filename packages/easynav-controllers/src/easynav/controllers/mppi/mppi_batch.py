"""MppiBatch: the sampled controls, their rollouts and what the critics score them against."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from easynav.controllers.mppi.collision_model import CollisionModel
from easynav.core.robot import RobotLimits
from easynav.core.types import Costmap2D

#: How much farther along the path than a rollout travelled (m) its end may count as reaching
#: (see :meth:`MppiBatch.furthest_reached_index`): the robot may stand a little off the path,
#: ahead of its projection.
PROGRESS_SLACK = 0.2


@dataclass(slots=True)
class MppiBatch:
    """One optimisation's batch, shared by every critic (arrays are ``float32``).

    Controls ``vx``, ``wz`` (S×T, after the limits), the rollouts ``x``, ``y``, ``yaw`` (S×T, the
    pose after each step of ``dt``), ``costs`` (S) that the critics add to. The local path
    (``path_xy`` P×2, ``path_yaw`` P, ``path_s`` P arc length from the robot's projection) starts
    at the robot's projection on the global path; ``path_is_final`` says whether it ends at the
    goal. ``goal`` is (x, y, yaw) of the last path pose, ``goal_dist`` the robot's straight
    distance to it (:attr:`remaining`: along the path). ``costmap`` is None when NavState has
    no ``map``; ``collision`` is the cycle's collision test over it (None: the CostCritic tests
    the cells under the poses only).

    Thread contract: built and scored in the RT thread; never shared.
    """

    vx: np.ndarray
    wz: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    costs: np.ndarray
    dt: float
    pose: tuple[float, float, float]
    velocity: tuple[float, float]
    limits: RobotLimits
    path_xy: np.ndarray
    path_yaw: np.ndarray
    path_s: np.ndarray
    path_is_final: bool
    goal: tuple[float, float, float]
    goal_dist: float
    costmap: Costmap2D | None = None
    collision: CollisionModel | None = None
    _furthest: int | None = field(default=None, repr=False)

    @property
    def remaining(self) -> float:
        """Length (m) of the path left from the robot's projection on it to the goal; ``inf``
        when the local path does not reach the goal.

        What the critics' "near the goal" thresholds (``threshold_to_consider``,
        ``near_goal_distance``) compare with, as Nav2 does since 2025 (it used the straight
        distance): where the path goes round an obstacle to a goal just behind it, the goal is
        near in a straight line but not along the path, and the goal critic, taking over from
        the path critics, pulled the robot straight at the obstacle (seen between the
        tb3_sandbox pillars: the robot crept along a pillar towards a goal 1.4 m away beyond
        it).
        """
        if not self.path_is_final or len(self.path_s) == 0:
            return math.inf
        return float(self.path_s[-1])

    @property
    def samples(self) -> int:
        """Number of sampled control sequences (S)."""
        return int(self.vx.shape[0])

    @property
    def steps(self) -> int:
        """Number of steps of each sequence (T)."""
        return int(self.vx.shape[1])

    def furthest_reached_index(self) -> int:
        """Index of the local-path point nearest to any rollout's end (the furthest one),
        among the points no farther along the path than that rollout travelled (plus
        :data:`PROGRESS_SLACK`).

        Computed once per batch (Nav2's "furthest reached path point"): the critics that look
        ahead of it (path align, path follow, path angle) share it. The arc-length bound (as
        Nav2 since 2026) keeps a rollout that cuts across a bend of the path from "reaching"
        the path beyond the bend: where the path turns round an obstacle, a rollout driven
        through the obstacle ends next to the path behind it, and the path-follow critic then
        pulled every rollout towards that point, across the obstacle (seen on the TurtleBot3
        sandbox: the robot left the passage between two pillars towards the one the path
        turned round, and stopped against it).
        """
        if self._furthest is None:
            if len(self.path_xy) <= 1:
                self._furthest = 0
            else:
                ends = np.stack((self.x[:, -1], self.y[:, -1]), axis=1)
                path = self.path_xy.astype(np.float32)
                d2 = (
                    np.sum(ends * ends, axis=1)[:, None]
                    - 2.0 * ends @ path.T
                    + np.sum(path * path, axis=1)[None, :]
                )
                travelled = np.abs(self.vx).sum(axis=1, dtype=np.float32) * np.float32(self.dt)
                beyond = self.path_s.astype(np.float32)[None, :] > (
                    travelled[:, None] + np.float32(PROGRESS_SLACK))
                beyond[:, 0] = False  # the robot's projection is always reachable
                d2[beyond] = np.inf
                self._furthest = int(np.argmin(d2, axis=1).max())
        return self._furthest
