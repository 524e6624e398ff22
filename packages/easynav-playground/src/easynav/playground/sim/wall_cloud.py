"""The wall cloud of a multi-level world: points on every surface its laser can see.

A 3D map for the NavMap stack (``easynav_bonxai_maps_manager/BonxaiMapsManager``'s
``bonxai_path_file``, which the NavMap AMCL scores its scans on) of a world that has no cloud of
its own: generated from the world's ``levels`` section (:class:`MultiLevelWorld`), one point per
``spacing`` (0.1 m, at the centres of a face's squares) on

- every face of every solid (walls, railings, pillars, furniture),
- the top and the sides of every floor slab (the ground floor seen from a ramp, the upper
  floor's edge seen from below),
- the surface and the sides of every ramp's wedge (seen from the ground floor near its foot).

Each point is pushed ``offset`` (1 cm) off its face, outward: it falls in the voxel where a laser
hit on that face lands (a face on a voxel boundary would otherwise be in the voxel behind it).
Points outside the world's ``bounds`` (the room's outer faces) or inside another solid (where
walls meet) are dropped; duplicates (at the output precision, 1 mm) removed. The result is
deterministic: ``python -m easynav.playground.sim.wall_cloud`` regenerates
``worlds/two_floors.walls.ply`` byte for byte (a test checks it).

Thread contract: pure functions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from easynav.playground.sim.multilevel import MultiLevelWorld, Ramp

#: Distance between the points on a face (m).
DEFAULT_SPACING = 0.1
#: How far each point is pushed off its face, outward (m).
DEFAULT_OFFSET = 0.01


def _axis_samples(lo: float, hi: float, spacing: float) -> np.ndarray:
    """The midpoints of the fewest equal intervals of ``[lo, hi]`` at most ``spacing`` long
    (a face from 0 to 8 m at 0.1 m: 0.05, 0.15, ... 7.95, the centres of 0.1 m voxels)."""
    n = max(1, int(np.ceil((hi - lo) / spacing - 1e-9)))
    return lo + (np.arange(n) + 0.5) * ((hi - lo) / n)


def _face(fixed_axis: int, value: float, ranges: tuple[tuple[float, float], tuple[float, float]],
          normal_sign: float, spacing: float, offset: float) -> np.ndarray:
    """Points on the axis-aligned face ``coord[fixed_axis] = value`` over ``ranges`` (the other
    two axes, in increasing axis order), pushed ``offset`` along ``normal_sign``."""
    a = _axis_samples(*ranges[0], spacing)
    b = _axis_samples(*ranges[1], spacing)
    ga, gb = np.meshgrid(a, b, indexing="ij")
    pts = np.empty((ga.size, 3))
    others = [i for i in range(3) if i != fixed_axis]
    pts[:, fixed_axis] = value + normal_sign * offset
    pts[:, others[0]] = ga.ravel()
    pts[:, others[1]] = gb.ravel()
    return pts


def _box_faces(box: tuple[float, float, float, float, float, float], spacing: float,
               offset: float) -> list[np.ndarray]:
    """Points on the six faces of ``(x0, y0, z0, x1, y1, z1)``."""
    lo, hi = box[:3], box[3:]
    faces = []
    for axis in range(3):
        others = [i for i in range(3) if i != axis]
        ranges = ((lo[others[0]], hi[others[0]]), (lo[others[1]], hi[others[1]]))
        faces.append(_face(axis, lo[axis], ranges, -1.0, spacing, offset))
        faces.append(_face(axis, hi[axis], ranges, +1.0, spacing, offset))
    return faces


def _ramp_surface(ramp: Ramp, spacing: float, offset: float) -> list[np.ndarray]:
    """Points on a ramp's sloped surface (pushed along its upward normal) and on the two
    triangular sides of its wedge (from the lower floor up to the surface)."""
    x0, y0, x1, y1 = ramp.area
    xs, ys = _axis_samples(x0, x1, spacing), _axis_samples(y0, y1, spacing)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    gz = np.asarray(ramp.height(gx, gy), dtype=float)
    g = ramp.gradient()
    normal = np.array([-g[0], -g[1], 1.0])
    normal /= np.linalg.norm(normal)
    top = np.stack((gx.ravel(), gy.ravel(), gz.ravel()), axis=1) + offset * normal
    sides = []
    along = ramp.axis
    across = 1 - along
    lo_c, hi_c = ramp.area[across], ramp.area[across + 2]
    u = _axis_samples(ramp.area[along], ramp.area[along + 2], spacing)
    for c, sign in ((lo_c, -1.0), (hi_c, +1.0)):
        for ui in u:
            x, y = (ui, c) if along == 0 else (c, ui)
            h = float(ramp.height(x, y))
            for z in _axis_samples(ramp.z_low, max(h, ramp.z_low + 1e-6), spacing):
                p = [x, y, z]
                p[across] += sign * offset
                sides.append(p)
    return [top, np.array(sides, dtype=float).reshape(-1, 3)]


def wall_cloud(levels: MultiLevelWorld, spacing: float = DEFAULT_SPACING,
               offset: float = DEFAULT_OFFSET) -> np.ndarray:
    """``(N, 3)`` points on the surfaces of ``levels`` (see the module documentation), sorted
    (x, then y, then z) and rounded to 1 mm."""
    if not (spacing > 0.0 and offset >= 0.0):
        raise ValueError(f"wall_cloud: need spacing > 0 and offset >= 0, got {spacing}, {offset}")
    parts: list[np.ndarray] = []
    solids = [(s.x0, s.y0, s.z0, s.x1, s.y1, s.z1) for s in levels.solids]
    for box in solids:
        parts += _box_faces(box, spacing, offset)
    for f in levels.floors:
        x0, y0, x1, y1 = f.area
        parts += _box_faces((x0, y0, f.z - f.thickness, x1, y1, f.z), spacing, offset)
    for ramp in levels.ramps:
        parts += _ramp_surface(ramp, spacing, offset)
    pts = np.concatenate([p for p in parts if len(p)], axis=0)
    bx0, by0, bx1, by1 = levels.bounds
    keep = (pts[:, 0] >= bx0) & (pts[:, 0] <= bx1) & (pts[:, 1] >= by0) & (pts[:, 1] <= by1)
    for x0, y0, z0, x1, y1, z1 in solids:  # strictly inside another solid: hidden
        inside = ((pts[:, 0] > x0) & (pts[:, 0] < x1) & (pts[:, 1] > y0) & (pts[:, 1] < y1)
                  & (pts[:, 2] > z0) & (pts[:, 2] < z1))
        keep &= ~inside
    pts = np.round(pts[keep], 3) + 0.0  # no -0.0
    pts = np.unique(pts, axis=0)  # sorted by x, then y, then z
    return pts


def ply_text(points: np.ndarray, comment: str = "") -> str:
    """``points`` as an ASCII PLY point cloud (x, y, z float, 1 mm)."""
    lines = ["ply", "format ascii 1.0"]
    if comment:
        lines += [f"comment {c}" for c in comment.splitlines()]
    lines += [f"element vertex {len(points)}", "property float x", "property float y",
              "property float z", "end_header"]
    lines += [f"{x:.3f} {y:.3f} {z:.3f}" for x, y, z in points]
    return "\n".join(lines) + "\n"


def wall_cloud_path(description: str | Path) -> Path:
    """Where a world's wall cloud is: ``<stem>.walls.ply`` beside its description."""
    description = Path(description)
    return description.with_name(f"{description.stem}.walls.ply")


def write_wall_cloud(description: str | Path, out: str | Path | None = None) -> Path:
    """Write the wall cloud of a multi-level world description to ``out`` (default:
    :func:`wall_cloud_path`). Returns the path written.

    Raises:
        ValueError: the description has no ``levels`` section.
    """
    description = Path(description)
    levels = MultiLevelWorld.from_description_file(description)
    path = Path(out) if out is not None else wall_cloud_path(description)
    path.write_text(ply_text(
        wall_cloud(levels),
        f"walls, railings, slabs and ramps of the {description.stem} world (one point per "
        f"{DEFAULT_SPACING:g} m, {DEFAULT_OFFSET:g} m off each face), generated from "
        f"{description.name} by easynav.playground.sim.wall_cloud"))
    return path


if __name__ == "__main__":
    import sys

    from easynav.playground.world_description import WORLDS_DIR

    target = sys.argv[1] if len(sys.argv) > 1 else WORLDS_DIR / "two_floors.yaml"
    print(write_wall_cloud(target))
