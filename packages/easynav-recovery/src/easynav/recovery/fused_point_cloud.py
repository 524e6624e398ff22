"""FusedPointCloud: the valid point perceptions of NavState in one frame, cached per scan."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps, voxel_downsample_indices
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState


class FusedPointCloud:
    """Points of the valid, ungrouped point perceptions, fused into a target frame.

    ``update(nav_state, target_frame)`` fuses (through the TF buffer of ``namespace``), keeps
    the points with ``z_min <= z <= z_max`` (``z_min < z < z_max`` with ``strict_z``) and, with a
    ``leaf_size``, downsamples them on a voxel grid. The result is cached until a perception is
    replaced in NavState (new data, expiry), so an RT reflex that checks every cycle fuses each
    scan once.

    After ``update``: ``valid_count`` is the number of valid perceptions, ``usable_count`` those
    that could be transformed into the target frame (a perception whose frame is unknown to TF
    cannot be used: callers that must fail safe treat ``usable_count == 0`` as blindness), and
    ``stamp`` the newest stamp used (NaN without any).

    Each perception is transformed at its own stamp: its points are where they were relative
    to the target frame *then*. For a frame that moves with the robot, :meth:`carried_to_latest`
    moves them to where they are relative to it at the newest ``odom → target`` transform
    (Nav2's collision monitor calls this base shift correction): a reflex otherwise measures
    its distances from where the robot was when the sensor fired, up to a few tenths of a
    second ago on a loaded machine (0.1 m at 0.3 m/s).

    Thread contract: one instance per thread (not locked). Exceptions: ``ValueError`` for an
    empty target frame.
    """

    def __init__(
        self,
        namespace: str = "",
        z_min: float = -math.inf,
        z_max: float = math.inf,
        strict_z: bool = False,
        leaf_size: float | None = None,
        logger: Any = None,
    ) -> None:
        self.namespace = namespace
        self.z_min = z_min
        self.z_max = z_max
        self.strict_z = strict_z
        self.leaf_size = leaf_size
        self.logger = logger
        self.valid_count = 0
        self.usable_count = 0
        self.stamp = math.nan
        self._points = np.empty((0, 3))
        self._point_stamps = np.empty(0)
        self._frame = ""
        self._sources: list[PointPerception] = []
        self._carried: tuple[tuple, np.ndarray, float] | None = None
        self.points_stamp = math.nan

    def update(self, nav_state: NavState, target_frame: str) -> np.ndarray:
        """The fused ``(N, 3)`` points in ``target_frame`` (shared: do not modify)."""
        if not target_frame:
            raise ValueError("FusedPointCloud: target frame is empty")
        perceptions = nav_state.get_no_group(PointPerception)
        valid = {key: p for key, p in sorted(perceptions.items()) if p.valid}
        sources = list(valid.values())
        if (
            target_frame == self._frame
            and len(sources) == len(self._sources)
            and all(a is b for a, b in zip(sources, self._sources, strict=True))
        ):
            return self._points
        buffer = get_tf_buffer(self.namespace)
        usable = {
            key: p
            for key, p in valid.items()
            if p.frame_id == target_frame or buffer.can_transform(target_frame, p.frame_id)
        }
        # One perception at a time: each point keeps the time its robot-frame position is of,
        # and downsampling never trades a point of one scan for another's older one.
        parts, stamps = [], []
        for key, p in usable.items():
            part = self._filtered(
                PointPerceptionsOps({key: p}, buffer, self.logger).fuse(target_frame).as_points())
            parts.append(part)
            stamps.append(np.full(part.shape[0], self._taken_at(buffer, p, target_frame)))
        points = np.concatenate(parts) if parts else np.empty((0, 3))
        stamps = np.concatenate(stamps) if stamps else np.empty(0)
        self._points = points
        self._point_stamps = stamps
        self._carried = None
        self._frame = target_frame
        self._sources = sources  # kept alive, so identity comparisons stay meaningful
        self.valid_count = len(valid)
        self.usable_count = len(usable)
        self.stamp = max((p.stamp for p in usable.values()), default=math.nan)
        return points

    def _filtered(self, points: np.ndarray) -> np.ndarray:
        """``points`` within the z limits, downsampled to ``leaf_size``."""
        if points.shape[0] and (self.z_min > -math.inf or self.z_max < math.inf):
            z = points[:, 2]
            if self.strict_z:
                points = points[(z > self.z_min) & (z < self.z_max)]
            else:
                points = points[(z >= self.z_min) & (z <= self.z_max)]
        if self.leaf_size and points.shape[0] > 1:
            points = points[voxel_downsample_indices(points, self.leaf_size)]
        return points

    @staticmethod
    def _taken_at(buffer, perception: PointPerception, target_frame: str) -> float:
        """The time the fused points of ``perception`` describe relative to ``target_frame``:
        its stamp, unless the transform was not known then and the fusion took the latest
        (a perception in a fixed frame such as odom, newer than the last odometry)."""
        frame, stamp = perception.frame_id, perception.stamp
        if frame == target_frame or buffer.can_transform(target_frame, frame, stamp):
            return float(stamp)
        try:
            return buffer.latest_common_time(target_frame, frame)
        except LookupError:
            return float(stamp)

    def carried_to_latest(self, odom_frame: str) -> np.ndarray:
        """The points of the last :meth:`update`, moved into its target frame as that frame is
        at the newest ``odom_frame → target`` transform: each perception's points by the
        target's motion since the perception's stamp (planar: x, y and yaw of the odometry).

        Points whose stamp TF cannot place (older than its window, newer than the last
        transform, no odometry at all) are returned as they are: the correction only ever
        uses measured motion. Afterwards :attr:`points_stamp` is the time the returned points
        describe, the oldest of theirs (the newest transform's stamp for the points carried,
        their own for the others; NaN without points): the robot may have moved since by
        what no transform has told yet. Cached until the next scan or a new newest odometry
        transform; any thread that owns the instance.
        """
        points = self._points
        own = float(self._point_stamps.min()) if points.shape[0] else math.nan
        self.points_stamp = own
        if points.shape[0] == 0 or not self._frame or odom_frame == self._frame:
            return points
        buffer = get_tf_buffer(self.namespace)
        try:
            latest_stamp, latest = buffer.lookup_transform_values(odom_frame, self._frame)
        except LookupError:
            return points
        key = (odom_frame, latest_stamp, latest)  # a transform re-sent with its stamp: new
        if self._carried is not None and self._carried[0] == key:
            self.points_stamp = self._carried[2]
            return self._carried[1]
        lx, ly, lyaw = _planar(latest)
        out = points.copy()
        oldest = math.inf
        for stamp in np.unique(self._point_stamps):
            if not math.isfinite(stamp):
                continue
            try:
                _, then = buffer.lookup_transform_values(odom_frame, self._frame, float(stamp))
            except LookupError:
                oldest = min(oldest, float(stamp))
                continue
            oldest = min(oldest, latest_stamp)
            tx, ty, tyaw = _planar(then)
            # then -> odom -> now: rotate by the yaw turned, shift by the way driven.
            c0, s0 = math.cos(tyaw), math.sin(tyaw)
            c1, s1 = math.cos(lyaw), math.sin(lyaw)
            rows = self._point_stamps == stamp
            px, py = points[rows, 0], points[rows, 1]
            ox, oy = tx + c0 * px - s0 * py - lx, ty + s0 * px + c0 * py - ly
            out[rows, 0] = c1 * ox + s1 * oy
            out[rows, 1] = -s1 * ox + c1 * oy
        self.points_stamp = oldest
        self._carried = (key, out, oldest)
        return out


def _planar(values) -> tuple[float, float, float]:
    """x, y and yaw of a transform ``(tx, ty, tz, qx, qy, qz, qw)``."""
    tx, ty, _, qx, qy, qz, qw = values
    return tx, ty, math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
