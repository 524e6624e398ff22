"""CollisionSafetyReflex (easynav_collision_safety_reflex/CollisionSafetyReflex): brakes when
the command about to be sent would hit an obstacle within its stopping distance.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.tf import get_tf_buffer
from easynav.core.types import Twist
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.safety_reflex_base import SafetyReflexBase
from easynav.recovery.fused_point_cloud import FusedPointCloud

#: Below this linear speed (m/s) the robot is not moving (rotating in place is allowed blind).
MOVING_SPEED = 1e-3


class CollisionSafetyReflex(SafetyReflexBase):
    """Collision braking for whatever command is about to be sent (controller or mitigation).

    Every RT cycle with a linear speed ``v`` commanded:

    1. the points of the valid point perceptions, fused into the robot footprint frame, with
       ``z_min_filter <= z <= robot_geometry.height``, downsampled to ``downsample_leaf_size``
       (fused once per scan, see :class:`FusedPointCloud`);
    2. broad phase: the box around the robot disc of radius ``R = robot_geometry.radius +
       safety_margin``, stretched by the stopping distance ``v²/(2·brake_acc)`` in the direction
       of motion (forward, backward or sideways);
    3. closest approach per point: with the commanded twist held, each point moves relative to
       the robot at ``(-vx + wz·y, -vy - wz·x)``; it is a collision when, within the stopping time
       ``v/brake_acc``, a point that is getting closer comes within ``R`` of the centre. A point
       already inside the disc but getting farther does not count, so the robot can move away.

    On a collision it brakes: a zero OVERRIDE, published as is. Fail-safe: commanded to move
    with no usable point perception (none valid, or none whose frame TF can transform), it
    brakes too. Rotating in place (no linear speed) is never braked.

    Parameters: ``brake_acc`` (0.5 m/s², > 0), ``safety_margin`` (0.1 m), ``z_min_filter``
    (0.0 m), ``downsample_leaf_size`` (0.1 m, > 0).

    Thread contract: as :class:`SafetyReflexBase` (``check`` in the RT thread).
    """

    READS = (keys.CMD_VEL, keys.NAVIGATION_PAUSED, keys.SAFETY_STATUS, keys.PROPOSAL_TAKEOVER)
    WRITES = (keys.PROPOSAL_OVERRIDE,)
    PARAMETERS = (
        Param("brake_acc", 0.5, "deceleration assumed for the stopping distance", "m/s²", gt=0.0),
        Param("safety_margin", 0.1, "margin added to robot_geometry.radius", "m", ge=0.0),
        Param("z_min_filter", 0.0, "points below this height are ignored", "m", dynamic=False),
        Param("downsample_leaf_size", 0.1, "voxel size of the fused cloud",
              "m", gt=0.0, dynamic=False),
    )

    def on_initialize(self) -> None:
        self.brake_acc = self.params.brake_acc
        self.safety_margin = self.params.safety_margin
        self.z_min_filter = self.params.z_min_filter
        self.downsample_leaf_size = self.params.downsample_leaf_size
        geometry = self.get_robot_geometry()
        self.robot_radius = geometry.radius
        self.robot_height = geometry.height
        self._cloud = FusedPointCloud(
            self.context.namespace,
            z_min=self.z_min_filter,
            z_max=self.robot_height,
            leaf_size=self.downsample_leaf_size,
            logger=self.logger,
        )

    def check(self, nav_state: NavState, commanded: Twist | None) -> bool:
        if commanded is None:
            return False
        vx, vy, wz = commanded.vx, commanded.vy, commanded.wz
        speed = math.hypot(vx, vy)
        if not speed > MOVING_SPEED:  # NaN commands are discarded by the mux anyway
            return False
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        points = self._cloud.update(nav_state, frame)
        if self._cloud.usable_count == 0:
            self.reason = (
                "no valid point perception while commanded to move"
                if self._cloud.valid_count == 0
                else f"no point perception can be transformed into '{frame}'"
            )
            return True
        hit = first_collision(
            points, vx, vy, wz, self.robot_radius + self.safety_margin, self.brake_acc
        )
        if hit is None:
            return False
        self.reason = (
            f"imminent collision with a point at ({hit[0]:.2f}, {hit[1]:.2f}) m at {speed:.2f} m/s"
        )
        return True


def first_collision(
    points: np.ndarray, vx: float, vy: float, wz: float, reach: float, brake_acc: float
) -> tuple[float, float] | None:
    """The ``(x, y)`` of a point the robot would hit before stopping, or None.

    ``points`` ``(N, 3)`` in the robot footprint frame; ``reach`` is the radius of the robot disc
    (with its margin); braking at ``brake_acc`` from the linear speed ``hypot(vx, vy)``.
    """
    if points.shape[0] == 0:
        return None
    speed = math.hypot(vx, vy)
    t_stop = speed / brake_acc
    stop_distance = speed * speed / (2.0 * brake_acc)
    ext_x = stop_distance * vx / speed if speed > 0.0 else 0.0
    ext_y = stop_distance * vy / speed if speed > 0.0 else 0.0
    x, y = points[:, 0], points[:, 1]
    box = (
        (x >= -reach + min(0.0, ext_x))
        & (x <= reach + max(0.0, ext_x))
        & (y >= -reach + min(0.0, ext_y))
        & (y <= reach + max(0.0, ext_y))
    )
    if not np.any(box):
        return None
    px, py = x[box], y[box]
    rel_x = -vx + wz * py
    rel_y = -vy - wz * px
    rel_sq = rel_x * rel_x + rel_y * rel_y
    moving = rel_sq > 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        t_star = np.where(moving, -(px * rel_x + py * rel_y) / np.where(moving, rel_sq, 1.0), 0.0)
    approaching = moving & (t_star > 0.0)
    t_closest = np.minimum(t_star, t_stop)
    cx = px + rel_x * t_closest
    cy = py + rel_y * t_closest
    hits = approaching & (cx * cx + cy * cy <= reach * reach)
    if not np.any(hits):
        return None
    i = int(np.argmax(hits))
    return float(px[i]), float(py[i])
