"""ColisionChecker: the controller base's last check of a command against nearby points.

The original's ``ControllerMethodBase`` collision check (parameters ``colision_checker.*`` on
controller_node, spelt with one "l" as there). Pure numpy, no ROS: controller_node gathers the
points and applies the verdict (see :mod:`easynav.system.controller_node`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from easynav.core.plugins.declarations import Param

#: Node-level parameters of controller_node (defaults of the original).
COLISION_CHECKER_PARAMETERS = (
    Param("colision_checker.active", False,
          "deprecated (the recovery system brakes before obstacles): check each controller "
          "command against the point perceptions; zero it on a collision"),
    Param("colision_checker.debug_markers", False,
          "publish each check's box and points on collision_area (visualization_msgs/"
          "MarkerArray), red on a collision"),
    # The original's own copies of the robot's shape (0.35 m, 0.5 m): deprecated, unset by
    # default, system_node.robot_geometry.radius / height stand in (controller_node resolves).
    Param("colision_checker.robot_radius", math.nan,
          "deprecated: system_node robot_geometry.radius", "m", gt=0.0, allow_nan=True),
    Param("colision_checker.robot_height", math.nan,
          "deprecated: system_node robot_geometry.height (points above it are ignored)", "m",
          gt=0.0, allow_nan=True),
    Param("colision_checker.brake_acc", 0.5, "deceleration assumed to stop", "m/s^2", gt=0.0),
    Param("colision_checker.safety_margin", 0.1, "margin of the search box around the robot",
          "m", ge=0.0),
    Param("colision_checker.z_min_filter", 0.0, "points below this height are ignored", "m"),
    Param("colision_checker.downsample_leaf_size", 0.1, "voxel size of the points checked", "m",
          gt=0.0),
)

#: Points farther than this (m, on either axis) from the robot are never checked.
SEARCH_RANGE = 2.0


@dataclass(frozen=True, slots=True)
class Collision:
    """The first point the command runs into: where, when (s) and how close (m)."""

    point: tuple[float, float, float]
    time: float
    distance: float


class ColisionChecker:
    """Whether a command ``(v, w)`` brings the robot's circle onto a point before it can stop.

    Points are in the robot frame (x ahead, y left, z up). Kept: the box
    x in [-(r + m), r + m + v^2 / (2 a)] (mirrored when reversing), |y| <= r + m, z in
    [z_min, height]. For each point p, its motion relative to the robot under the command is
    ``dp/dt = (-v + w p_y, -w p_x)``; the distance to the robot's centre is taken at the time of
    closest approach clamped to the stopping time ``T = |v| / a``: a collision when the point is
    approaching (closest approach ahead in time) and that distance is <= r.

    Differences from the original: the original tested the closest approach only when it fell
    within ``T``, so a point straight ahead that the robot reaches before ``T`` but "passes"
    after it was missed; here the distance at ``T`` counts too. A robot turning in place
    (``v == 0``) never collides (a circle turning on itself sweeps nothing new), where the
    original stopped it for any point inside its radius. Reversing is checked behind.

    Thread contract: immutable after construction; any thread. Exceptions: ``ValueError`` for
    a negative radius or height, a non-positive deceleration or leaf size, or a negative
    margin.
    """

    def __init__(
        self,
        robot_radius: float = 0.35,
        robot_height: float = 0.5,
        brake_acc: float = 0.5,
        safety_margin: float = 0.1,
        z_min_filter: float = 0.0,
        downsample_leaf_size: float = 0.1,
    ) -> None:
        for name, value in (("brake_acc", brake_acc),
                            ("downsample_leaf_size", downsample_leaf_size)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"colision_checker.{name} = {value}: must be finite and > 0")
        # The robot's shape comes from robot_geometry, where 0 is legal (a point robot; no
        # height: nothing to check).
        for name, value in (("robot_radius", robot_radius), ("robot_height", robot_height)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"colision_checker.{name} = {value}: must be finite and >= 0")
        if not (math.isfinite(safety_margin) and safety_margin >= 0.0):
            raise ValueError(f"colision_checker.safety_margin = {safety_margin}: must be >= 0")
        self.robot_radius = float(robot_radius)
        self.robot_height = float(robot_height)
        self.brake_acc = float(brake_acc)
        self.safety_margin = float(safety_margin)
        self.z_min_filter = float(z_min_filter)
        self.downsample_leaf_size = float(downsample_leaf_size)

    @classmethod
    def from_parameters(cls, values: Mapping[str, Any]) -> ColisionChecker:
        """A checker from the ``colision_checker.*`` values (names with or without prefix)."""
        def get(name: str) -> float:
            return values.get(f"colision_checker.{name}", values.get(name))

        return cls(
            get("robot_radius"), get("robot_height"), get("brake_acc"), get("safety_margin"),
            get("z_min_filter"), get("downsample_leaf_size"),
        )

    def box(self, v: float) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """``(min_xyz, max_xyz)`` of the points that matter for a linear speed ``v``."""
        reach = self.robot_radius + self.safety_margin
        stopping = v * v / (2.0 * self.brake_acc)
        x_min, x_max = -reach, reach
        if v >= 0.0:
            x_max += stopping
        else:
            x_min -= stopping
        return (x_min, -reach, self.z_min_filter), (x_max, reach, self.robot_height)

    def check(self, points: np.ndarray, v: float, w: float) -> Collision | None:
        """The collision (the one soonest) of command ``(v, w)`` among ``points`` ``(N, 3)``,
        or None when the command is safe."""
        if not (math.isfinite(v) and math.isfinite(w)) or v == 0.0:
            return None
        pts = np.asarray(points, dtype=float).reshape(-1, 3)
        low, high = self.box(v)
        keep = np.all((pts >= low) & (pts <= high), axis=1)
        pts = pts[keep]
        if len(pts) == 0:
            return None
        px, py = pts[:, 0], pts[:, 1]
        vx = -v + w * py
        vy = -w * px
        speed2 = vx * vx + vy * vy
        approach = -(px * vx + py * vy)  # > 0: the point is getting closer
        t_star = np.where(speed2 > 1e-12, approach / np.where(speed2 > 1e-12, speed2, 1.0), 0.0)
        t = np.minimum(t_star, abs(v) / self.brake_acc)
        dx, dy = px + vx * t, py + vy * t
        miss = np.hypot(dx, dy)
        hit = (approach > 0.0) & (miss <= self.robot_radius)
        if not np.any(hit):
            return None
        first = int(np.flatnonzero(hit)[np.argmin(t[hit])])
        return Collision(tuple(float(c) for c in pts[first]), float(t[first]), float(miss[first]))
