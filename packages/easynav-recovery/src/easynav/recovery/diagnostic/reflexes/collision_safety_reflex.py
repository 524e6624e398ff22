"""CollisionSafetyReflex (easynav_collision_safety_reflex/CollisionSafetyReflex): brakes when
the command about to be sent would hit an obstacle within its stopping distance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, Topic
from easynav.core.types import Twist
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.safety_reflex_base import SafetyReflexBase
from easynav.recovery.fused_point_cloud import FusedPointCloud

#: Below this linear speed (m/s) the robot is not moving (rotating in place is allowed blind).
MOVING_SPEED = 1e-3
#: Topic of the debug markers (relative: in the node's namespace, as the original's).
MARKERS_TOPIC = "collision_area"
#: Marker lifetime (s): a marker not renewed (the robot stopped) vanishes, as the original's.
MARKER_LIFETIME = 0.2


@dataclass(frozen=True)
class CollisionZone:
    """What one check looked at, in the robot footprint frame ``frame``: the box
    ``lower``–``upper`` (x, y, z) around the robot disc stretched by the stopping distance,
    the ``points`` (N, 3) inside it, and whether a collision was found (``imminent``)."""

    frame: str
    stamp: float
    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    points: np.ndarray
    imminent: bool


class CollisionSafetyReflex(SafetyReflexBase):
    """Collision braking for whatever command is about to be sent (controller or mitigation).

    Every RT cycle with a linear speed ``v`` commanded:

    1. the points of the valid point perceptions, fused into the robot footprint frame, with
       ``z_min_filter <= z <= robot_geometry.height``, downsampled to ``downsample_leaf_size``
       (fused once per scan, see :class:`FusedPointCloud`), and moved by the robot's odometry
       since each perception's stamp (``odom → robot footprint``), as Nav2's collision
       monitor corrects its sources for the base's motion;
    2. broad phase: the box around the robot disc of radius ``R = robot_geometry.radius +
       safety_margin``, stretched by the stopping distance ``v²/(2·brake_acc)`` in the direction
       of motion (forward, backward or sideways);
    3. closest approach per point: with the commanded twist held, each point moves relative to
       the robot at ``(-vx + wz·y, -vy - wz·x)``; it is a collision when, within the latency
       plus the stopping time ``v/brake_acc``, a point that is getting closer comes within
       ``R`` of the centre. The latency is the points' age: from the newest odometry that
       carried them (or their own stamp) to now; the box of step 2 grows by ``v·latency``. A point
       already inside the disc but getting farther does not count, so the robot can move away.

    On a collision it brakes: a zero OVERRIDE, published as is. Fail-safe: commanded to move
    with no usable point perception (none valid, or none whose frame TF can transform), it
    brakes too. Rotating in place (no linear speed) is never braked.

    Parameters: ``brake_acc`` (0.5 m/s², > 0), ``safety_margin`` (0.1 m), ``z_min_filter``
    (0.0 m), ``downsample_leaf_size`` (0.1 m, > 0), ``debug_markers`` (false).

    ``debug_markers`` (as the original's): every check that looks at the points (commanded to
    move, a usable perception) publishes on ``collision_area`` (visualization_msgs/MarkerArray,
    namespace-relative, depth 10) a DELETEALL, the checked box (CUBE) and the points inside it
    (SPHERE_LIST, 3 cm), in the robot footprint frame, green, red when a collision is imminent,
    alpha 0.25, lifetime 0.2 s. The last :class:`CollisionZone` is kept in :attr:`last_zone`
    either way (None before the first look).

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
        Param("debug_markers", False, "publish the checked box and points on collision_area"),
    )
    TOPICS = (
        Topic(MARKERS_TOPIC, "visualization_msgs/msg/MarkerArray", "pub", "reliable, depth 10",
              "with debug_markers: the checked box and the points in it, red on a collision"),
    )

    def __init__(self) -> None:
        super().__init__()
        self.last_zone: CollisionZone | None = None
        self._marker_publisher: Any = None

    def on_initialize(self) -> None:
        self._destroy_publisher()
        self.debug_markers = self.params.debug_markers
        self.last_zone = None
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
        if self.context.node is not None:
            try:
                from visualization_msgs.msg import MarkerArray
            except ImportError:
                if self.debug_markers:
                    self.logger.warning(f"{self.plugin_name}.debug_markers: visualization_msgs "
                                        "is not installed: no markers")
            else:
                self._marker_publisher = self.context.node.create_publisher(
                    MarkerArray, MARKERS_TOPIC, 10)

    def on_cleanup(self) -> None:
        self._destroy_publisher()

    def _destroy_publisher(self) -> None:
        publisher, self._marker_publisher = self._marker_publisher, None
        if publisher is not None and self.context.node is not None:
            self.context.node.destroy_publisher(publisher)

    def check(self, nav_state: NavState, commanded: Twist | None) -> bool:
        if commanded is None:
            return False
        vx, vy, wz = commanded.vx, commanded.vy, commanded.wz
        speed = math.hypot(vx, vy)
        if not speed > MOVING_SPEED:  # NaN commands are discarded by the mux anyway
            return False
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        frame = tf_info.robot_footprint_frame
        self._cloud.update(nav_state, frame)
        if self._cloud.usable_count == 0:
            self.reason = (
                "no valid point perception while commanded to move"
                if self._cloud.valid_count == 0
                else f"no point perception can be transformed into '{frame}'"
            )
            return True
        # Where the points are as of the newest odometry, not where they were when the sensor
        # fired; what the robot drove since that odometry (a loaded machine delivers it late
        # too) is the latency, at the commanded twist.
        points = self._cloud.carried_to_latest(tf_info.odom_frame)
        latency = self.now() - self._cloud.points_stamp
        latency = latency if latency > 0.0 else 0.0  # NaN (no points) and clock skew: none
        reach = self.robot_radius + self.safety_margin
        hit = first_collision(points, vx, vy, wz, reach, self.brake_acc, latency)
        if self.debug_markers:
            self._show(frame, points, vx, vy, reach, hit is not None, latency)
        if hit is None:
            return False
        self.reason = (
            f"imminent collision with a point at ({hit[0]:.2f}, {hit[1]:.2f}) m at {speed:.2f} m/s"
        )
        return True


    def _show(self, frame: str, points: np.ndarray, vx: float, vy: float, reach: float,
              imminent: bool, latency: float = 0.0) -> None:
        x_lo, x_hi, y_lo, y_hi = stopping_box(vx, vy, reach, self.brake_acc, latency)
        lower = (x_lo, y_lo, self.z_min_filter)
        upper = (x_hi, y_hi, self.robot_height)
        inside = points[in_box(points, lower, upper)] if points.shape[0] else points
        stamp = self._cloud.stamp if math.isfinite(self._cloud.stamp) else self.now()
        self.last_zone = CollisionZone(frame, stamp, lower, upper, inside, imminent)
        if self._marker_publisher is not None:
            self._marker_publisher.publish(zone_markers(self.last_zone))


def stopping_box(vx: float, vy: float, reach: float, brake_acc: float,
                 latency: float = 0.0) -> tuple[float, float, float, float]:
    """``(x_min, x_max, y_min, y_max)`` of the broad phase: the box around the robot disc of
    radius ``reach``, stretched in the direction of motion by the way driven in ``latency``
    seconds plus the stopping distance ``v²/(2·brake_acc)``."""
    speed = math.hypot(vx, vy)
    stop_distance = speed * latency + speed * speed / (2.0 * brake_acc)
    ext_x = stop_distance * vx / speed if speed > 0.0 else 0.0
    ext_y = stop_distance * vy / speed if speed > 0.0 else 0.0
    return (-reach + min(0.0, ext_x), reach + max(0.0, ext_x),
            -reach + min(0.0, ext_y), reach + max(0.0, ext_y))


def in_box(points: np.ndarray, lower, upper) -> np.ndarray:
    """Mask of the ``points`` (N, 3) within ``lower``–``upper`` (bounds included)."""
    return np.all((points >= np.asarray(lower)) & (points <= np.asarray(upper)), axis=1)


def zone_markers(zone: CollisionZone) -> Any:
    """The original's debug markers of ``zone``: a visualization_msgs/MarkerArray with a
    DELETEALL, the box (CUBE, id 1) and the points (SPHERE_LIST, id 2), namespace
    ``collision_zone`` (:func:`~easynav.system.ros.collision_markers.collision_markers`). Needs
    visualization_msgs (ImportError otherwise)."""
    from easynav.system.ros.collision_markers import collision_markers

    return collision_markers(
        zone.frame, zone.stamp, zone.lower, zone.upper, zone.points, zone.imminent,
        MARKER_LIFETIME,
    )


def first_collision(
    points: np.ndarray, vx: float, vy: float, wz: float, reach: float, brake_acc: float,
    latency: float = 0.0,
) -> tuple[float, float] | None:
    """The ``(x, y)`` of a point the robot would hit before stopping, or None.

    ``points`` ``(N, 3)`` in the robot footprint frame as it was ``latency`` seconds ago (the
    robot has driven on at the commanded twist since); ``reach`` is the radius of the robot
    disc (with its margin); braking at ``brake_acc`` from the linear speed ``hypot(vx, vy)``.
    """
    if points.shape[0] == 0:
        return None
    speed = math.hypot(vx, vy)
    t_stop = latency + speed / brake_acc
    x_lo, x_hi, y_lo, y_hi = stopping_box(vx, vy, reach, brake_acc, latency)
    x, y = points[:, 0], points[:, 1]
    box = (x >= x_lo) & (x <= x_hi) & (y >= y_lo) & (y <= y_hi)
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
