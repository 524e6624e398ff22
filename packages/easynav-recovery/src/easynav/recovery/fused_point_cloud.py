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
        self._frame = ""
        self._sources: list[PointPerception] = []

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
        ops = PointPerceptionsOps(usable, buffer, self.logger).fuse(target_frame)
        points = ops.as_points()
        if points.shape[0] and (self.z_min > -math.inf or self.z_max < math.inf):
            z = points[:, 2]
            if self.strict_z:
                mask = (z > self.z_min) & (z < self.z_max)
            else:
                mask = (z >= self.z_min) & (z <= self.z_max)
            points = points[mask]
        if self.leaf_size and points.shape[0] > 1:
            points = points[voxel_downsample_indices(points, self.leaf_size)]
        self._points = points
        self._frame = target_frame
        self._sources = sources  # kept alive, so identity comparisons stay meaningful
        self.valid_count = len(valid)
        self.usable_count = len(usable)
        self.stamp = max((p.stamp for p in usable.values()), default=math.nan)
        return points
