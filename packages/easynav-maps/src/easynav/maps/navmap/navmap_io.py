"""The original's ``.navmap`` file: an envelope around the CDR-serialised NavMap message.

Format (navmap_ros/src/navmap_ros/navmap_io.cpp): 8 bytes ``NAVMAP\\0\\0``, uint32 version 1,
uint64 payload size (little endian), then the ROS 2 CDR serialisation of
``navmap_ros_interfaces/msg/NavMap``:

    std_msgs/Header header                 (int32 sec, uint32 nanosec, string frame_id)
    float32[] positions_x, positions_y, positions_z
    bool has_vertex_rgba
    uint8[] colors_r, colors_g, colors_b, colors_a
    uint32[] navcels_v0, navcels_v1, navcels_v2
    NavMapSurface[] surfaces               (string frame_id, uint32[] navcels)
    NavMapLayer[] layers                   (Header header, string name, uint8 type 0/1/2,
                                            uint8[] data_u8, float32[] data_f32,
                                            float64[] data_f64)

A file without the magic is read as a bare CDR payload (as the original's loader does).
Positions are stored as float32 (the message's type): a NavMap read back has its vertices
rounded to float32.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from easynav.maps.map_format_error import MapFormatError
from easynav.maps.navmap.cdr import CdrBuffer
from easynav.maps.navmap.navmap import LAYER_DTYPES, NavMap, Surface

MAGIC = b"NAVMAP\x00\x00"
VERSION = 1
_HEADER = struct.Struct("<8sIQ")


def navmap_to_cdr(navmap: NavMap, stamp: float = 0.0) -> bytes:
    """CDR payload of the NavMap message for ``navmap`` (header frame = ``navmap.frame_id``)."""
    buf = CdrBuffer()
    sec = int(np.floor(stamp))
    _write_header(buf, sec, int(round((stamp - sec) * 1e9)), navmap.frame_id)
    for axis in range(3):
        buf.write_array(navmap.vertices[:, axis], np.float32)
    colors = navmap.colors
    buf.write("?", colors is not None)
    for channel in range(4):
        buf.write_array(colors[:, channel] if colors is not None else [], np.uint8)
    for corner in range(3):
        buf.write_array(navmap.faces[:, corner], np.uint32)
    buf.write("I", len(navmap.surfaces))
    for surface in navmap.surfaces:
        buf.write_string(surface.frame_id)
        buf.write_array(surface.navcels, np.uint32)
    names = navmap.list_layers()
    buf.write("I", len(names))
    for name in names:
        data = navmap.layer(name)
        _write_header(buf, 0, 0, "")
        buf.write_string(name)
        kind = LAYER_DTYPES.index(data.dtype)
        buf.write("B", kind)
        for k, dtype in enumerate(LAYER_DTYPES):
            buf.write_array(data if k == kind else [], dtype)
    return buf.getvalue()


def navmap_from_cdr(payload: bytes, source: str = "<bytes>") -> NavMap:
    """NavMap of a CDR payload of the NavMap message; :class:`MapFormatError` naming
    ``source`` when it is truncated or inconsistent."""
    buf = CdrBuffer(payload, source)
    buf.read("i", "header.stamp.sec")
    buf.read("I", "header.stamp.nanosec")
    frame_id = buf.read_string("header.frame_id")
    limit = len(payload)
    xyz = [buf.read_array(np.float32, f"positions_{a}", limit) for a in "xyz"]
    if not len(xyz[0]) == len(xyz[1]) == len(xyz[2]):
        raise MapFormatError(
            f"{source}: positions_x/y/z have {len(xyz[0])}/{len(xyz[1])}/{len(xyz[2])} values"
        )
    has_rgba = buf.read("?", "has_vertex_rgba")
    rgba = [buf.read_array(np.uint8, f"colors_{c}", limit) for c in "rgba"]
    tri = [buf.read_array(np.uint32, f"navcels_v{k}", limit) for k in range(3)]
    if not len(tri[0]) == len(tri[1]) == len(tri[2]):
        raise MapFormatError(f"{source}: navcels_v0/v1/v2 differ in length")
    n_vertices, n_cels = len(xyz[0]), len(tri[0])
    faces = np.column_stack(tri).astype(np.int64) if n_cels else np.zeros((0, 3), np.int64)
    if n_cels and int(faces.max()) >= n_vertices:
        raise MapFormatError(
            f"{source}: a NavCel indexes vertex {int(faces.max())}, there are {n_vertices}"
        )
    colors = None
    if has_rgba:
        if any(len(c) != n_vertices for c in rgba):
            raise MapFormatError(f"{source}: has_vertex_rgba with colours not one per vertex")
        colors = np.column_stack(rgba)
    surfaces = []
    for k in range(buf.read("I", "surfaces count")):
        fid = buf.read_string(f"surfaces[{k}].frame_id")
        cels = buf.read_array(np.uint32, f"surfaces[{k}].navcels", limit)
        if len(cels) and int(cels.max()) >= n_cels:
            raise MapFormatError(f"{source}: surface {k} lists NavCel {int(cels.max())} "
                                 f"of {n_cels}")
        surfaces.append(Surface(fid, cels))
    vertices = np.column_stack(xyz).astype(np.float64) if n_vertices else np.zeros((0, 3))
    navmap = NavMap(vertices, faces, surfaces=surfaces, colors=colors, frame_id=frame_id)
    for k in range(buf.read("I", "layers count")):
        what = f"layers[{k}]"
        buf.read("i", what + ".header.stamp.sec")
        buf.read("I", what + ".header.stamp.nanosec")
        buf.read_string(what + ".header.frame_id")
        name = buf.read_string(what + ".name")
        kind = buf.read("B", what + ".type")
        arrays = [buf.read_array(dt, f"{what}.data", limit) for dt in LAYER_DTYPES]
        if kind > 2:
            raise MapFormatError(f"{source}: layer {name!r} has type {kind} (0=U8, 1=F32, 2=F64)")
        data = arrays[kind]
        if len(data) != n_cels:
            raise MapFormatError(
                f"{source}: layer {name!r} has {len(data)} values for {n_cels} NavCels"
            )
        navmap.set_layer(name, data, LAYER_DTYPES[kind])
    return navmap


def save_navmap(navmap: NavMap, path: str | os.PathLike, stamp: float = 0.0) -> Path:
    """Write ``navmap`` as the original's ``.navmap`` file; returns the path."""
    path = Path(path)
    payload = navmap_to_cdr(navmap, stamp)
    path.write_bytes(_HEADER.pack(MAGIC, VERSION, len(payload)) + payload)
    return path


def load_navmap(path: str | os.PathLike) -> NavMap:
    """Read a ``.navmap`` file. :class:`FileNotFoundError` or :class:`MapFormatError`, naming
    the file."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such NavMap file")
    raw = path.read_bytes()
    if raw[:8] == MAGIC:
        if len(raw) < _HEADER.size:
            raise MapFormatError(f"{path}: truncated .navmap header ({len(raw)} bytes)")
        _, version, size = _HEADER.unpack_from(raw)
        if version != VERSION:
            raise MapFormatError(f"{path}: .navmap version {version}, only {VERSION} is known")
        payload = raw[_HEADER.size :]
        if len(payload) < size:
            raise MapFormatError(
                f"{path}: header announces a {size}-byte payload, the file holds {len(payload)}"
            )
        payload = payload[:size]
    else:
        if not raw:
            raise MapFormatError(f"{path}: empty file")
        payload = raw
    return navmap_from_cdr(payload, str(path))


def _write_header(buf: CdrBuffer, sec: int, nanosec: int, frame_id: str) -> None:
    buf.write("i", sec)
    buf.write("I", nanosec)
    buf.write_string(frame_id)
