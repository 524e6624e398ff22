"""Builders of NavMaps: from an occupancy grid (the original's ``from_occupancy_grid``), from a
mesh file (PLY, OBJ) and from a point cloud (2.5-D Delaunay)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from easynav.maps.map_format_error import MapFormatError
from easynav.maps.map_yaml import load_map_yaml
from easynav.maps.navmap.navmap import LETHAL_OBSTACLE, NO_INFORMATION, NavMap, Surface
from easynav.maps.occupancy_grid import OccupancyGrid
from easynav.maps.voxel.voxel_sources import _PLY_TYPES

#: Largest origin yaw (rad) taken as unrotated (the original ignores the yaw altogether).
MAX_ORIGIN_YAW = 1e-6


def occupancy_to_u8(values: np.ndarray) -> np.ndarray:
    """The original's ``occ_to_u8``: -1 → 255 (unknown), ≥ 100 → 254, else
    ``lround(v / 100 · 254)``."""
    v = np.asarray(values, dtype=np.int16)
    out = np.floor(np.clip(v, 0, 100) * (LETHAL_OBSTACLE / 100.0) + 0.5).astype(np.uint8)
    out[v >= 100] = LETHAL_OBSTACLE
    out[v < 0] = NO_INFORMATION
    return out


def navmap_from_occupancy_grid(grid: OccupancyGrid, frame_id: str | None = None) -> NavMap:
    """NavMap of an occupancy grid, as the original's ``navmap_ros::from_occupancy_grid``.

    Vertices at the ``(W+1)·(H+1)`` cell corners (z = origin z), two NavCels per cell —
    ``(i,j),(i+1,j),(i+1,j+1)`` and ``(i,j),(i+1,j+1),(i,j+1)``, cell ``(i, j)`` giving NavCels
    ``2·(j·W+i)`` and ``+1`` — every cell, whatever its value; a uint8 layer ``occupancy`` with
    :func:`occupancy_to_u8` of the cell. Raises ``ValueError`` for a rotated origin.
    """
    if abs(grid.origin.yaw) > MAX_ORIGIN_YAW:
        raise ValueError(
            f"occupancy grid origin has yaw {grid.origin.yaw:.6f} rad: a NavMap from a grid "
            "needs an unrotated origin (re-save the map with origin yaw 0)"
        )
    h, w = grid.data.shape
    res = float(grid.resolution)
    ox, oy, oz = float(grid.origin.x), float(grid.origin.y), float(grid.origin.z)
    jj, ii = np.meshgrid(np.arange(h + 1), np.arange(w + 1), indexing="ij")
    vertices = np.column_stack([
        ox + ii.ravel() * res, oy + jj.ravel() * res, np.full(ii.size, oz)
    ])
    cj, ci = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    v00 = (cj * (w + 1) + ci).ravel()
    v10, v11, v01 = v00 + 1, v00 + w + 2, v00 + w + 1
    faces = np.empty((2 * h * w, 3), dtype=np.int64)
    faces[0::2] = np.column_stack([v00, v10, v11])
    faces[1::2] = np.column_stack([v00, v11, v01])
    frame = frame_id if frame_id is not None else (grid.header.frame_id or "map")
    navmap = NavMap(vertices, faces, surfaces=[Surface(frame, np.arange(len(faces)))],
                    frame_id=frame)
    navmap.set_layer("occupancy", np.repeat(occupancy_to_u8(grid.data).ravel(), 2), np.uint8)
    return navmap


def navmap_from_map_yaml(path: str | os.PathLike, frame_id: str = "map") -> NavMap:
    """NavMap of a ROS map_server map (YAML + image; the ``occmap_path_file`` parameter).

    Raises :class:`FileNotFoundError` or :class:`MapFormatError` naming the file."""
    grid = load_map_yaml(path, frame_id)
    try:
        return navmap_from_occupancy_grid(grid, frame_id)
    except ValueError as exc:
        raise MapFormatError(f"{path}: {exc}") from None


def navmap_from_points(
    points: np.ndarray, max_edge_length: float | None = None, frame_id: str = "map"
) -> NavMap:
    """NavMap of a 2.5-D point cloud: Delaunay triangulation over xy (scipy.spatial), each
    point keeping its z; triangles with an edge longer than ``max_edge_length`` (3-D) dropped
    (None keeps all). Points sharing an xy are merged (the first kept).

    Raises ``ValueError`` for fewer than 3 distinct points and ``ImportError`` naming the extra
    when scipy is missing.
    """
    try:
        from scipy.spatial import Delaunay
    except ImportError:
        raise ImportError(
            "building a NavMap from a point cloud needs scipy "
            "(pip install easynav-maps[navmap])"
        ) from None
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    points = points[np.isfinite(points).all(axis=1)]
    _, keep = np.unique(points[:, :2], axis=0, return_index=True)
    points = points[np.sort(keep)]
    if len(points) < 3:
        raise ValueError(f"a NavMap needs at least 3 distinct xy points, got {len(points)}")
    faces = Delaunay(points[:, :2]).simplices.astype(np.int64)
    if max_edge_length is not None and max_edge_length > 0:
        tri = points[faces]
        edges = np.linalg.norm(tri - tri[:, [1, 2, 0]], axis=2)
        faces = faces[(edges <= max_edge_length).all(axis=1)]
    # counter-clockwise in xy, so that the normals point up
    tri = points[faces]
    cross = ((tri[:, 1, 0] - tri[:, 0, 0]) * (tri[:, 2, 1] - tri[:, 0, 1])
             - (tri[:, 1, 1] - tri[:, 0, 1]) * (tri[:, 2, 0] - tri[:, 0, 0]))
    faces[cross < 0] = faces[cross < 0][:, [0, 2, 1]]
    return NavMap(points, faces, frame_id=frame_id)


def read_obj(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (N,3), faces (M,3))`` of a Wavefront OBJ file: ``v`` and ``f`` lines
    (``f a b c``, ``a/t/n`` forms, negative indices; polygons fan-triangulated), the rest
    ignored. :class:`MapFormatError` naming the file and line."""
    path = Path(path)
    vertices: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    with path.open("r", encoding="utf-8", errors="replace") as stream:
        for lineno, line in enumerate(stream, 1):
            words = line.split()
            if not words:
                continue
            try:
                if words[0] == "v":
                    vertices.append([float(w) for w in words[1:4]])
                    if len(vertices[-1]) != 3:
                        raise ValueError("a vertex needs x y z")
                elif words[0] == "f":
                    ids = [int(w.split("/")[0]) for w in words[1:]]
                    if len(ids) < 3:
                        raise ValueError("a face needs at least 3 vertices")
                    ids = [i - 1 if i > 0 else len(vertices) + i for i in ids]
                    faces.extend((ids[0], ids[k], ids[k + 1]) for k in range(1, len(ids) - 1))
            except ValueError as exc:
                raise MapFormatError(f"{path}:{lineno}: {exc}: {line.strip()!r}") from None
    if not faces:
        raise MapFormatError(f"{path}: no faces ('f' lines) in this OBJ file")
    return np.asarray(vertices, dtype=np.float64).reshape(-1, 3), np.asarray(faces, np.int64)


def read_ply_mesh(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (N,3), faces (M,3))`` of a PLY mesh (ascii or binary; a ``vertex`` element
    with x y z, then a ``face`` element with a ``vertex_indices``/``vertex_index`` list;
    polygons fan-triangulated). The property types are those of the point-cloud PLY reader of
    :mod:`easynav.maps.voxel.voxel_sources`. :class:`MapFormatError` naming the file."""
    path = Path(path)
    raw = path.read_bytes()
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise MapFormatError(f"{path}: not a PLY file (no 'ply' ... 'end_header' header)")
    body = raw[raw.index(b"\n", end) + 1 :]
    fmt, elements = None, []
    for line in raw[:end].decode("ascii", "replace").splitlines()[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements:
            if words[1] == "list":
                types = (_PLY_TYPES.get(words[2]), _PLY_TYPES.get(words[3]))
                elements[-1][2].append((words[4], types))
            elif words[1] in _PLY_TYPES:
                elements[-1][2].append((words[2], _PLY_TYPES[words[1]]))
            else:
                raise MapFormatError(f"{path}: unknown PLY property type {words[1]!r}")
    names = [e[0] for e in elements]
    if "vertex" not in names or "face" not in names:
        raise MapFormatError(f"{path}: a PLY mesh needs 'vertex' and 'face' elements")
    if fmt == "ascii":
        vertices, faces = _ply_ascii(path, body, elements)
    elif fmt in ("binary_little_endian", "binary_big_endian"):
        vertices, faces = _ply_binary(path, body, elements, "<" if "little" in fmt else ">")
    else:
        raise MapFormatError(f"{path}: unknown PLY format {fmt!r}")
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise MapFormatError(f"{path}: a face indexes a vertex outside 0..{len(vertices) - 1}")
    return vertices, faces


def _fan(polys: list[list[int]]) -> np.ndarray:
    out = [(p[0], p[k], p[k + 1]) for p in polys for k in range(1, len(p) - 1)]
    return np.asarray(out, dtype=np.int64).reshape(-1, 3)


def _xyz(path: Path, props: list, columns) -> np.ndarray:
    names = [n for n, _ in props]
    if not {"x", "y", "z"} <= set(names):
        raise MapFormatError(f"{path}: PLY vertices need x, y and z properties")
    return np.column_stack([np.asarray(columns[n], dtype=np.float64) for n in "xyz"])


def _ply_ascii(path: Path, body: bytes, elements: list) -> tuple[np.ndarray, np.ndarray]:
    rows = iter(body.decode("ascii", "replace").splitlines())
    vertices, polys = None, []
    for name, count, props in elements:
        block = [next(rows, "").split() for _ in range(count)]
        if any(not r for r in block):
            raise MapFormatError(f"{path}: {count} '{name}' rows announced, fewer found")
        if name == "vertex":
            if any(isinstance(t, tuple) for _, t in props):
                raise MapFormatError(f"{path}: list properties on PLY vertices")
            try:
                table = np.array([r[: len(props)] for r in block], dtype=np.float64)
            except ValueError:
                raise MapFormatError(f"{path}: malformed PLY vertex rows") from None
            vertices = _xyz(path, props, {n: table[:, i] for i, (n, _) in enumerate(props)})
        elif name == "face":
            try:
                for r in block:  # the list is the first property of a face in practice
                    n = int(r[0])
                    polys.append([int(v) for v in r[1 : 1 + n]])
            except ValueError:
                raise MapFormatError(f"{path}: malformed PLY face rows") from None
    return vertices, _fan(polys)


def _ply_binary(path: Path, body: bytes, elements: list, order: str):
    pos, vertices, faces = 0, None, None
    for name, count, props in elements:
        if all(not isinstance(t, tuple) for _, t in props):
            dtype = np.dtype([(n, order + t) for n, t in props])
            if pos + count * dtype.itemsize > len(body):
                raise MapFormatError(f"{path}: {count} '{name}' announced, the data is shorter")
            table = np.frombuffer(body, dtype=dtype, count=count, offset=pos)
            pos += count * dtype.itemsize
            if name == "vertex":
                vertices = _xyz(path, props, table)
            continue
        if name != "face" or len(props) != 1:
            raise MapFormatError(f"{path}: list properties are read only as the face's only one")
        count_t, index_t = props[0][1]
        ct, it = np.dtype(order + count_t), np.dtype(order + index_t)
        # Fast path: all triangles, fixed-size records.
        tri = np.dtype([("n", ct), ("v", it, (3,))])
        if pos + count * tri.itemsize <= len(body):
            table = np.frombuffer(body, dtype=tri, count=count, offset=pos)
            if (table["n"] == 3).all():
                faces = table["v"].astype(np.int64)
                pos += count * tri.itemsize
                continue
        polys = []
        for _ in range(count):
            if pos + ct.itemsize > len(body):
                raise MapFormatError(f"{path}: face data shorter than announced")
            n = int(np.frombuffer(body, ct, 1, pos)[0])
            pos += ct.itemsize
            if pos + n * it.itemsize > len(body):
                raise MapFormatError(f"{path}: face data shorter than announced")
            polys.append(np.frombuffer(body, it, n, pos).tolist())
            pos += n * it.itemsize
        faces = _fan(polys)
    return vertices, faces


def navmap_from_mesh_file(path: str | os.PathLike, frame_id: str = "map") -> NavMap:
    """NavMap of a PLY or OBJ mesh file. :class:`FileNotFoundError` or
    :class:`MapFormatError` naming the file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such mesh file")
    suffix = path.suffix.lower()
    if suffix == ".ply":
        vertices, faces = read_ply_mesh(path)
    elif suffix == ".obj":
        vertices, faces = read_obj(path)
    else:
        raise MapFormatError(f"{path}: unknown mesh format {suffix!r} (.ply and .obj are read)")
    try:
        return NavMap(vertices, faces, frame_id=frame_id)
    except ValueError as exc:
        raise MapFormatError(f"{path}: {exc}") from None
