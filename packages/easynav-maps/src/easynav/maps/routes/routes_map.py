"""RoutesMap: route segments, their YAML file (the original's format) and their cells on a grid.

Routes YAML (the original's)::

    routes: [route0, route1]
    route0:
      start: {x: 0.0, y: 0.0, z: 0.0, qx: 0.0, qy: 0.0, qz: 0.0, qw: 1.0}
      end:   {x: 1.0, y: 0.0}
    route1: ...

``z`` defaults to 0, the quaternion to the identity. Pure functions and plain values, any
thread.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from easynav.core.nav_state_keys import NavStateKey
from easynav.core.types import Costmap2D, Pose
from easynav.maps.map_format_error import MapFormatError

ROUTES = NavStateKey(
    "routes",
    "RoutesMap",
    "the route segments (id, start pose, end pose) in the map frame (RoutesMapsManager).",
)

_POSE_KEYS = ("x", "y", "z", "qx", "qy", "qz", "qw")


@dataclass(frozen=True, slots=True)
class RouteSegment:
    """A straight route from ``start`` to ``end`` (poses in the map frame), named ``id``."""

    id: str
    start: Pose
    end: Pose


@dataclass(frozen=True, slots=True)
class RoutesMap:
    """An ordered, immutable list of :class:`RouteSegment` (NavState ``routes``).

    Thread contract: immutable; a writer stores a new one.
    """

    segments: tuple[RouteSegment, ...] = ()

    def __len__(self) -> int:
        return len(self.segments)

    def __iter__(self) -> Iterator[RouteSegment]:
        return iter(self.segments)

    def __getitem__(self, index: int) -> RouteSegment:
        return self.segments[index]

    @classmethod
    def default(cls) -> RoutesMap:
        """The original's default: one segment ``route0`` from (0, 0, 0) to (1, 0, 0)."""
        return cls((RouteSegment("route0", Pose(), Pose(1.0, 0.0, 0.0)),))


def _pose(doc: Any, where: str) -> Pose:
    if not isinstance(doc, dict):
        raise MapFormatError(f"{where}: expected a mapping {{x, y, z, qx, qy, qz, qw}}")
    unknown = sorted(str(k) for k in doc if k not in _POSE_KEYS)
    if unknown:
        raise MapFormatError(f"{where}: unknown key(s) {', '.join(unknown)}")
    values = {}
    for key, default in zip(_POSE_KEYS, (None, None, 0.0, 0.0, 0.0, 0.0, 1.0), strict=True):
        value = doc.get(key, default)
        if value is None:
            raise MapFormatError(f"{where}: '{key}' is missing")
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(
            value
        ):
            raise MapFormatError(f"{where}.{key} = {value!r}: must be a finite number")
        values[key] = float(value)
    norm = math.sqrt(sum(values[k] ** 2 for k in ("qx", "qy", "qz", "qw")))
    if norm < 1e-9:
        raise MapFormatError(f"{where}: the quaternion is zero")
    return Pose(
        values["x"], values["y"], values["z"],
        values["qx"] / norm, values["qy"] / norm, values["qz"] / norm, values["qw"] / norm,
    )


def parse_routes(doc: Any, source: str = "routes") -> RoutesMap:
    """A :class:`RoutesMap` from the parsed YAML document; :class:`MapFormatError` names the
    file and the key at fault."""
    if not isinstance(doc, dict):
        raise MapFormatError(f"{source}: expected a mapping with a 'routes' list")
    names = doc.get("routes")
    if not isinstance(names, list) or not all(isinstance(n, str) and n for n in names):
        raise MapFormatError(f"{source}: 'routes' must be a list of route names, got {names!r}")
    if len(set(names)) != len(names):
        raise MapFormatError(f"{source}: 'routes' names a route twice: {names}")
    segments = []
    for name in names:
        entry = doc.get(name)
        if not isinstance(entry, dict) or "start" not in entry or "end" not in entry:
            raise MapFormatError(f"{source}: route '{name}' needs 'start' and 'end' poses")
        segments.append(
            RouteSegment(
                name, _pose(entry["start"], f"{source}: {name}.start"),
                _pose(entry["end"], f"{source}: {name}.end"),
            )
        )
    return RoutesMap(tuple(segments))


def load_routes_yaml(path: str | os.PathLike) -> RoutesMap:
    """Read a routes YAML. Raises :class:`FileNotFoundError` or :class:`MapFormatError`."""
    source = Path(path)
    if not source.is_file():
        raise FileNotFoundError(f"routes file not found: {source}")
    try:
        doc = yaml.safe_load(source.read_text())
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise MapFormatError(f"{source}: not valid YAML ({exc})") from None
    return parse_routes(doc, str(source))


def _pose_doc(pose: Pose) -> dict[str, float]:
    return {k: float(getattr(pose, k)) for k in _POSE_KEYS}


def routes_to_doc(routes: RoutesMap) -> dict[str, Any]:
    """The YAML document of ``routes`` (segments without an id are named ``route<i>``)."""
    names = [s.id or f"route{i}" for i, s in enumerate(routes)]
    doc: dict[str, Any] = {"routes": names}
    for name, segment in zip(names, routes, strict=True):
        doc[name] = {"start": _pose_doc(segment.start), "end": _pose_doc(segment.end)}
    return doc


def save_routes_yaml(routes: RoutesMap, path: str | os.PathLike) -> Path:
    """Write ``routes`` in the original's format; raises :class:`OSError` naming the file."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(yaml.safe_dump(routes_to_doc(routes), sort_keys=False))
    return target


def on_route_cells(costmap: Costmap2D, routes: RoutesMap, route_width: float) -> np.ndarray:
    """``(height, width)`` bool: cells whose centre projects inside a segment (``0 <= t <= 1``,
    no end caps) within ``route_width`` of it (≤ 0: half a cell diagonal), +1e-6 m² as the
    original. Segments of zero length mark nothing."""
    res = costmap.resolution
    width = route_width if route_width > 0.0 else math.sqrt(2.0) * res * 0.5
    limit = width * width + 1e-6
    mask = np.zeros(costmap.data.shape, dtype=bool)
    for segment in routes:
        x0, y0 = segment.start.x, segment.start.y
        vx, vy = segment.end.x - x0, segment.end.y - y0
        c2 = vx * vx + vy * vy
        if c2 <= 0.0:
            continue
        # Only the cells of the segment's bounding box grown by the width can be on it.
        low_x, low_y = costmap.world_to_cell(min(x0, x0 + vx) - width, min(y0, y0 + vy) - width)
        high_x, high_y = costmap.world_to_cell(
            max(x0, x0 + vx) + width, max(y0, y0 + vy) + width
        )
        ix0, iy0 = max(0, int(low_x)), max(0, int(low_y))
        ix1, iy1 = min(costmap.width, int(high_x) + 1), min(costmap.height, int(high_y) + 1)
        if ix0 >= ix1 or iy0 >= iy1:
            continue
        cx, _ = costmap.cell_to_world(np.arange(ix0, ix1), 0)
        _, cy = costmap.cell_to_world(0, np.arange(iy0, iy1))
        wx = cx[None, :] - x0
        wy = cy[:, None] - y0
        t = (vx * wx + vy * wy) / c2
        dx = wx - t * vx
        dy = wy - t * vy
        near = (t >= 0.0) & (t <= 1.0) & (dx * dx + dy * dy <= limit)
        mask[iy0:iy1, ix0:ix1] |= near
    return mask
