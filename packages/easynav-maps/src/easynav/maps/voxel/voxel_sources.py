"""Where a voxel map starts from: an occupancy grid extruded to a wall height, or a point cloud
file (PCD and PLY read here, PCD written; compressed PCD and other formats through open3d, an
optional extra).

Pure functions, any thread. Exceptions name the file.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from easynav.core.types import LETHAL_OBSTACLE, Costmap2D
from easynav.maps.map_format_error import MapFormatError


def extrude_costmap(costmap: Costmap2D, wall_height: float, resolution: float) -> np.ndarray:
    """``(N, 3)`` voxel centres of the lethal cells of ``costmap`` stacked from the floor up to
    ``wall_height`` (m) every ``resolution`` (as the original Bonxai manager loads an occupancy
    grid: occupied cells become columns; free and unknown cells add nothing)."""
    if not wall_height > 0.0:
        raise ValueError(f"extrude_costmap: wall_height must be > 0, got {wall_height}")
    rows, cols = np.nonzero(costmap.data == LETHAL_OBSTACLE)
    x, y = costmap.cell_to_world(cols, rows)
    layers = (np.arange(max(1, int(round(wall_height / resolution)))) + 0.5) * resolution
    count = len(rows)
    return np.column_stack((
        np.repeat(np.asarray(x, dtype=np.float64), len(layers)),
        np.repeat(np.asarray(y, dtype=np.float64), len(layers)),
        np.tile(layers, count),
    ))


_PCD_TYPES = {("F", 4): "f4", ("F", 8): "f8", ("I", 1): "i1", ("I", 2): "i2", ("I", 4): "i4",
              ("I", 8): "i8", ("U", 1): "u1", ("U", 2): "u2", ("U", 4): "u4", ("U", 8): "u8"}


def read_pcd(path: str | os.PathLike) -> np.ndarray:
    """``(N, 3)`` float64 finite points of a PCD file (``DATA ascii`` or ``binary``; other
    fields skipped). ``binary_compressed`` needs open3d (:func:`read_point_cloud`).

    Raises :class:`FileNotFoundError` or :class:`MapFormatError` naming the file.
    """
    path = Path(path)
    raw = path.read_bytes()
    header: dict[str, list[str]] = {}
    offset = 0
    while True:
        end = raw.find(b"\n", offset)
        if end < 0:
            raise MapFormatError(f"{path}: PCD header has no DATA line")
        line = raw[offset:end].decode("ascii", "replace").strip()
        offset = end + 1
        if not line or line.startswith("#"):
            continue
        key, *values = line.split()
        header[key.upper()] = values
        if key.upper() == "DATA":
            break
    try:
        fields = header["FIELDS"]
        sizes = [int(v) for v in header["SIZE"]]
        types = header["TYPE"]
        counts = [int(v) for v in header.get("COUNT", ["1"] * len(fields))]
        points = int(header.get("POINTS", [0])[0]) or int(header["WIDTH"][0]) * int(
            header["HEIGHT"][0])
        mode = header["DATA"][0].lower()
    except (KeyError, ValueError, IndexError) as exc:
        raise MapFormatError(f"{path}: malformed PCD header ({exc})") from None
    if not {"x", "y", "z"} <= set(fields):
        raise MapFormatError(f"{path}: PCD has no x, y, z fields (fields: {fields})")
    if mode == "ascii":
        columns = []
        for name, count in zip(fields, counts, strict=True):
            columns.extend([name] + [f"{name}_{i}" for i in range(1, count)])
        text = raw[offset:].decode("ascii", "replace").split()
        if len(text) < points * len(columns):
            raise MapFormatError(f"{path}: PCD announces {points} points, holds fewer")
        values = np.array(text[: points * len(columns)], dtype=np.float64).reshape(points, -1)
        xyz = values[:, [columns.index("x"), columns.index("y"), columns.index("z")]]
    elif mode == "binary":
        try:
            dtype = np.dtype({
                "names": [f if c == 1 else f"{f}_" for f, c in zip(fields, counts, strict=True)],
                "formats": [(_PCD_TYPES[(t.upper(), s)], (c,)) if c > 1 else _PCD_TYPES[
                    (t.upper(), s)] for t, s, c in zip(types, sizes, counts, strict=True)],
            })
        except KeyError as exc:
            raise MapFormatError(f"{path}: unsupported PCD field type {exc}") from None
        if len(raw) - offset < points * dtype.itemsize:
            raise MapFormatError(f"{path}: PCD announces {points} points, holds fewer bytes")
        data = np.frombuffer(raw, dtype=dtype, count=points, offset=offset)
        xyz = np.column_stack([data[a].astype(np.float64) for a in "xyz"])
    else:
        raise MapFormatError(
            f"{path}: PCD DATA {mode} is not read natively: install open3d "
            "(pip install easynav-maps[open3d])"
        )
    return xyz[np.isfinite(xyz).all(axis=1)]


def write_pcd(path: str | os.PathLike, points: np.ndarray) -> Path:
    """Write ``points`` ``(N, 3)`` as a binary PCD (float32 x y z). Returns the path."""
    path = Path(path)
    xyz = np.ascontiguousarray(np.asarray(points, dtype=np.float32).reshape(-1, 3))
    header = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
        f"TYPE F F F\nCOUNT 1 1 1\nWIDTH {len(xyz)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(xyz)}\nDATA binary\n"
    )
    path.write_bytes(header.encode("ascii") + xyz.tobytes())
    return path


_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
              "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
              "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
              "float64": "f8"}


def read_ply(path: str | os.PathLike) -> np.ndarray:
    """``(N, 3)`` float64 finite points: the ``x y z`` of the ``vertex`` element of a PLY file
    (``ascii``, ``binary_little_endian`` or ``binary_big_endian``; other elements, such as
    faces, may follow and are ignored). Raises :class:`MapFormatError` naming the file."""
    path = Path(path)
    raw = path.read_bytes()
    end = raw.find(b"end_header")
    if not raw.startswith(b"ply") or end < 0:
        raise MapFormatError(f"{path}: not a PLY file (no 'ply' ... 'end_header' header)")
    body = raw[raw.index(b"\n", end) + 1:]
    fmt, elements, current = None, [], None
    for line in raw[:end].decode("ascii", "replace").splitlines()[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            current = (words[1], int(words[2]), [])
            elements.append(current)
        elif words[0] == "property" and current is not None:
            if words[1] == "list":
                current[2].append((words[-1], None))
            elif words[1] in _PLY_TYPES:
                current[2].append((words[2], _PLY_TYPES[words[1]]))
            else:
                raise MapFormatError(f"{path}: unknown PLY property type {words[1]!r}")
    if not elements or elements[0][0] != "vertex":
        raise MapFormatError(f"{path}: the first PLY element must be 'vertex'")
    _, count, properties = elements[0]
    names = [name for name, _ in properties]
    if not {"x", "y", "z"} <= set(names) or any(t is None for _, t in properties):
        raise MapFormatError(f"{path}: PLY vertices need scalar x, y and z properties")
    if fmt == "ascii":
        rows = body.decode("ascii", "replace").split("\n")[:count]
        try:
            table = np.array([row.split()[: len(names)] for row in rows], dtype=np.float64)
        except ValueError:
            raise MapFormatError(f"{path}: malformed PLY vertex rows") from None
        if table.shape != (count, len(names)):
            raise MapFormatError(f"{path}: {count} vertices announced, fewer found")
        columns = {name: table[:, i] for i, name in enumerate(names)}
    elif fmt in ("binary_little_endian", "binary_big_endian"):
        order = "<" if fmt == "binary_little_endian" else ">"
        dtype = np.dtype([(name, order + t) for name, t in properties])
        if len(body) < count * dtype.itemsize:
            raise MapFormatError(f"{path}: {count} vertices announced, the data is shorter")
        columns = np.frombuffer(body, dtype=dtype, count=count)
    else:
        raise MapFormatError(f"{path}: unknown PLY format {fmt!r}")
    xyz = np.column_stack([np.asarray(columns[k], dtype=np.float64) for k in ("x", "y", "z")])
    return xyz[np.isfinite(xyz).all(axis=1)]


def read_point_cloud(path: str | os.PathLike) -> np.ndarray:
    """``(N, 3)`` points of a PCD (native, or open3d for compressed data), a PLY (native) or any
    file open3d reads (XYZ, PTS). Raises :class:`FileNotFoundError` or :class:`MapFormatError`."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such point cloud file")
    if path.suffix.lower() == ".ply":
        return read_ply(path)
    if path.suffix.lower() == ".pcd":
        try:
            return read_pcd(path)
        except MapFormatError as exc:
            if "open3d" not in str(exc):
                raise
    try:
        import open3d
    except ImportError:
        raise MapFormatError(
            f"{path}: reading {path.suffix or 'this'} files needs open3d "
            "(pip install easynav-maps[open3d])"
        ) from None
    cloud = open3d.io.read_point_cloud(str(path))
    xyz = np.asarray(cloud.points, dtype=np.float64).reshape(-1, 3)
    if len(xyz) == 0:
        raise MapFormatError(f"{path}: open3d read no points")
    return xyz[np.isfinite(xyz).all(axis=1)]
