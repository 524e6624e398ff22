"""PointPerceptionsOps: a fluent view to filter, fuse, downsample and collapse point perceptions."""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from easynav.common.sensors.point_perception import PointPerception
from easynav.common.sensors.voxel_grid import voxel_downsample_indices
from easynav.common.tf import ExtrapolationError, TFBuffer, TransformError, get_tf_buffer
from easynav.common.tf.transform_math import rotation_matrix
from easynav.core.warning_throttle import WarningThrottle

_LOGGER = logging.getLogger("easynav.sensors")
_THROTTLE = WarningThrottle(period=5.0)


def transform_points(points: np.ndarray, values: tuple[float, ...]) -> np.ndarray:
    """``points`` (N, 3) moved by ``(tx, ty, tz, qx, qy, qz, qw)``, as a new float64 array.

    Column by column on purpose: ``points @ R.T`` goes through BLAS, which for a 3x3 operand is
    3-20x slower than three fused multiply-adds per column (measured in bench_perception.py).
    """
    tx, ty, tz, qx, qy, qz, qw = values
    rot = rotation_matrix(qx, qy, qz, qw)
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    out = np.empty((points.shape[0], 3), dtype=np.float64)
    scratch = np.empty(points.shape[0], dtype=np.float64)  # one temporary, reused
    for axis, (row, offset) in enumerate(zip(rot, (tx, ty, tz), strict=True)):
        column = out[:, axis]
        np.multiply(x, row[0], out=column)
        np.multiply(y, row[1], out=scratch)
        column += scratch
        np.multiply(z, row[2], out=scratch)
        column += scratch
        column += offset
    return out


class _Chunk:
    """Points of one source (a perception, or the fused cloud) and where they are."""

    __slots__ = ("points", "frame_id", "stamp", "label", "owned")

    def __init__(
        self, points: np.ndarray, frame_id: str, stamp: float, label: str, owned: bool
    ) -> None:
        self.points = points
        self.frame_id = frame_id
        self.stamp = stamp
        self.label = label
        self.owned = owned  # False while ``points`` is still the perception's own array


def _bounds(values: Sequence[float], name: str) -> tuple[float, float, float]:
    if len(values) != 3:
        raise ValueError(f"{name} must have 3 values (x, y, z; NaN = any), got {values!r}")
    x, y, z = (float(v) for v in values)
    return x, y, z


class PointPerceptionsOps:
    """Fluent operations on the valid perceptions among ``perceptions``.

    ``perceptions`` is a ``dict`` (keys are sensor ids, used in warnings: the usual input is
    ``nav_state.get_no_group(PointPerception)``) or any iterable of :class:`PointPerception`.
    Invalid perceptions (``valid`` False: older than ``forget_time``) are skipped.

    Every operation returns ``self`` and never modifies the perceptions' arrays. Before a
    :meth:`fuse` the operations apply to each perception in its own frame; after it, to the one
    fused cloud in the target frame. :meth:`as_points` returns a new, writable ``(N, 3)`` float64
    array (without a fuse, the points of every perception each in its own frame, concatenated).

    Thread contract: a short-lived object owned by the thread that created it; the TF buffer it
    reads is locked. Exceptions: ``ValueError`` for bad arguments (wrong length bounds, a
    resolution not > 0, an empty target frame), ``TypeError`` for an item that is not a
    PointPerception. TF failures never raise: the perception is skipped with a warning naming
    the sensor and the frames.
    """

    def __init__(
        self,
        perceptions: Mapping[str, PointPerception] | Iterable[PointPerception],
        tf_buffer: TFBuffer | None = None,
        logger: Any = None,
    ) -> None:
        items = (
            perceptions.items()
            if isinstance(perceptions, Mapping)
            else ((f"#{i}", p) for i, p in enumerate(perceptions))
        )
        self._chunks: list[_Chunk] = []
        for label, perception in items:
            if not isinstance(perception, PointPerception):
                raise TypeError(
                    f"PointPerceptionsOps: '{label}' is a {type(perception).__name__}, "
                    "not a PointPerception"
                )
            if perception.valid:
                self._chunks.append(
                    _Chunk(perception.points, perception.frame_id, perception.stamp, label, False)
                )
        self._tf_buffer = tf_buffer
        self._logger = logger if logger is not None else _LOGGER
        self._fused_frame: str | None = None
        self._fused_stamp: float | None = None

    # -- operations ---------------------------------------------------------------------------
    def filter(self, min_xyz: Sequence[float], max_xyz: Sequence[float]) -> PointPerceptionsOps:
        """Keep the points with ``min <= p <= max`` on every axis; a NaN bound is no bound."""
        low = _bounds(min_xyz, "filter min_xyz")
        high = _bounds(max_xyz, "filter max_xyz")
        axes = [
            (axis, lo, hi)
            for axis, (lo, hi) in enumerate(zip(low, high, strict=True))
            if not (math.isnan(lo) and math.isnan(hi))
        ]
        if not axes:
            return self
        for chunk in self._chunks:
            pts = chunk.points
            if pts.shape[0] == 0:
                continue
            mask = None
            for axis, lo, hi in axes:
                column = pts[:, axis]
                if not math.isnan(lo):
                    m = column >= lo
                    mask = m if mask is None else np.logical_and(mask, m, out=mask)
                if not math.isnan(hi):
                    m = column <= hi
                    mask = m if mask is None else np.logical_and(mask, m, out=mask)
            chunk.points = pts[mask]
            chunk.owned = True
        return self

    def downsample(self, resolution: float) -> PointPerceptionsOps:
        """One point per voxel of side ``resolution`` (floor bucketing; first point kept)."""
        resolution = float(resolution)
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"downsample resolution = {resolution!r} must be finite and > 0")
        for chunk in self._chunks:
            if chunk.points.shape[0] > 1:
                chunk.points = chunk.points[voxel_downsample_indices(chunk.points, resolution)]
                chunk.owned = True
        return self

    def collapse(self, values: Sequence[float]) -> PointPerceptionsOps:
        """Force coordinates: ``(nan, nan, 0.0)`` sets every z to 0 (NaN keeps that axis)."""
        forced = _bounds(values, "collapse values")
        axes = [(axis, v) for axis, v in enumerate(forced) if not math.isnan(v)]
        if not axes:
            return self
        for chunk in self._chunks:
            pts = chunk.points if chunk.owned else chunk.points.copy()
            for axis, v in axes:
                pts[:, axis] = v
            chunk.points = pts
            chunk.owned = True
        return self

    def fuse(
        self, target_frame: str, stamp: float | None = None, exact_time: bool = False
    ) -> PointPerceptionsOps:
        """Transform every perception into ``target_frame`` and merge them into one cloud.

        Each perception is transformed at ``stamp`` or, when None, at its own stamp. With
        ``exact_time`` False, a perception whose time is outside the TF window (the transform
        for it has not arrived yet, or is too old) uses the latest transform instead; with
        ``exact_time`` True it is skipped with a warning. A perception whose frame is unknown or
        not connected to ``target_frame``, or whose transform is not finite, is skipped with a
        warning naming the sensor and both frames. The fused cloud's stamp is ``stamp``, or the
        newest stamp of the perceptions fused.
        """
        if not target_frame:
            raise ValueError("fuse: target_frame is empty")
        buffer = self._tf_buffer if self._tf_buffer is not None else get_tf_buffer()
        parts: list[np.ndarray] = []
        owned = True
        newest = -math.inf
        for chunk in self._chunks:
            if chunk.frame_id == target_frame:
                parts.append(chunk.points)
                owned = chunk.owned
            else:
                transformed = self._transform(buffer, chunk, target_frame, stamp, exact_time)
                if transformed is None:
                    continue
                parts.append(transformed)
                owned = True
            newest = max(newest, chunk.stamp)
        if stamp is not None:
            fused_stamp = float(stamp)
        else:
            fused_stamp = newest if parts else 0.0
        if len(parts) == 1:
            points = parts[0]  # ``owned`` is that part's
        elif parts:
            points, owned = np.concatenate(parts), True
        else:
            points, owned = np.empty((0, 3)), True
        self._chunks = [_Chunk(points, target_frame, fused_stamp, "fused", owned)]
        self._fused_frame = target_frame
        self._fused_stamp = fused_stamp
        return self

    def _transform(
        self,
        buffer: TFBuffer,
        chunk: _Chunk,
        target_frame: str,
        stamp: float | None,
        exact_time: bool,
    ) -> np.ndarray | None:
        when = chunk.stamp if stamp is None else stamp
        try:
            try:
                _, values = buffer.lookup_transform_values(target_frame, chunk.frame_id, when)
            except ExtrapolationError:
                if exact_time:
                    raise
                _, values = buffer.lookup_transform_values(target_frame, chunk.frame_id, None)
        except TransformError as exc:
            _THROTTLE.warn(
                self._logger,
                ("fuse", chunk.label, chunk.frame_id, target_frame),
                f"Perception '{chunk.label}' skipped: no transform from '{chunk.frame_id}' to "
                f"'{target_frame}': {exc}",
            )
            return None
        if not all(math.isfinite(v) for v in values):
            _THROTTLE.warn(
                self._logger,
                ("fuse-nan", chunk.label, chunk.frame_id, target_frame),
                f"Perception '{chunk.label}' skipped: the transform from '{chunk.frame_id}' to "
                f"'{target_frame}' is not finite: {values}",
            )
            return None
        return transform_points(chunk.points, values)

    # -- results ------------------------------------------------------------------------------
    def as_points(self) -> np.ndarray:
        """The points as a new writable ``(N, 3)`` float64 array."""
        if len(self._chunks) == 1:
            chunk = self._chunks[0]
            return chunk.points if chunk.owned else chunk.points.copy()
        if not self._chunks:
            return np.empty((0, 3))
        return np.concatenate([c.points for c in self._chunks])

    @property
    def frame_id(self) -> str | None:
        """The target frame after :meth:`fuse`; otherwise the common frame, or None if mixed."""
        if self._fused_frame is not None:
            return self._fused_frame
        frames = {c.frame_id for c in self._chunks}
        return frames.pop() if len(frames) == 1 else None

    @property
    def stamp(self) -> float | None:
        """The fused cloud's stamp after :meth:`fuse`; otherwise the newest perception stamp."""
        if self._fused_stamp is not None:
            return self._fused_stamp
        return max((c.stamp for c in self._chunks), default=None)

    def __len__(self) -> int:
        return sum(c.points.shape[0] for c in self._chunks)
