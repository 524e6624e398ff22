"""NavMap .navmap file format (the original's CDR envelope) and builders."""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np
import pytest

from easynav.core.types import Header, Pose
from easynav.maps import MapFormatError, OccupancyGrid
from easynav.maps.navmap import NavMap, Surface
from easynav.maps.navmap.builders import (
    navmap_from_map_yaml,
    navmap_from_mesh_file,
    navmap_from_occupancy_grid,
    navmap_from_points,
    occupancy_to_u8,
)
from easynav.maps.navmap.navmap_io import load_navmap, navmap_from_cdr, save_navmap

DATA = Path(__file__).parent / "data"


def small_map() -> NavMap:
    verts = np.array([[0, 0, 0], [1, 0, 0.5], [1, 1, 0.25], [0, 1, 0]], dtype=np.float32)
    navmap = NavMap(verts, [[0, 1, 2], [0, 2, 3]], frame_id="map",
                    colors=np.arange(16, dtype=np.uint8).reshape(4, 4))
    navmap.set_layer("occupancy", np.array([0, 254], np.uint8))
    navmap.set_layer("elevation", np.array([0.25, -1.5], np.float32))
    navmap.set_layer("slope", np.array([0.1, 0.2], np.float64))
    return navmap


def test_round_trip(tmp_path):
    navmap = small_map()
    path = save_navmap(navmap, tmp_path / "m.navmap", stamp=12.5)
    back = load_navmap(path)
    np.testing.assert_array_equal(back.vertices, navmap.vertices)
    np.testing.assert_array_equal(back.faces, navmap.faces)
    np.testing.assert_array_equal(back.colors, navmap.colors)
    assert back.frame_id == "map"
    assert back.list_layers() == ["occupancy", "elevation", "slope"]
    for name in back.list_layers():
        assert back.layer(name).dtype == navmap.layer(name).dtype
        np.testing.assert_array_equal(back.layer(name), navmap.layer(name))
    assert [(s.frame_id, list(s.navcels)) for s in back.surfaces] == [("map", [0, 1])]
    raw = path.read_bytes()
    assert raw[:8] == b"NAVMAP\x00\x00"
    assert struct.unpack_from("<IQ", raw, 8) == (1, len(raw) - 20)


def test_round_trip_float64_vertices_rounded_to_float32(tmp_path):
    navmap = NavMap([[0.1, 0.2, 0.3], [1.1, 0, 0], [0, 1.3, 0]], [[0, 1, 2]])
    back = load_navmap(save_navmap(navmap, tmp_path / "f.navmap"))
    np.testing.assert_array_equal(back.vertices, navmap.vertices.astype(np.float32))


def _cdr_by_hand() -> bytes:
    """A NavMap message serialised byte by byte from navmap_ros_interfaces/msg (independent of
    the writer), with non-zero padding and trailing bytes as the original's files have (Fast-CDR
    does not clear its padding: the ROSCon 2025 workshop's excavation_urjc.navmap shows it)."""
    out = bytearray(b"\x00\x01\x00\x00")
    pad = lambda n: out.extend(b"\xaa" * ((-(len(out) - 4)) % n))  # noqa: E731

    def u32(v):
        pad(4)
        out.extend(struct.pack("<I", v))

    def string(s):
        u32(len(s) + 1)
        out.extend(s.encode() + b"\x00")

    out.extend(struct.pack("<iI", 7, 5))  # header stamp
    string("odom")
    for values in ([0.0, 2.0, 0.0, 2.0], [0.0, 0.0, 2.0, 2.0], [0.0, 0.0, 1.0, 1.0]):
        u32(len(values))
        out.extend(struct.pack("<4f", *values))
    out.extend(b"\x00")  # has_vertex_rgba
    for _ in range(4):
        u32(0)
    for column in ([0, 1], [1, 3], [2, 2]):
        u32(2)
        out.extend(struct.pack("<2I", *column))
    u32(0)  # no surfaces: the reader makes one of every NavCel, as the original's from_msg
    u32(2)  # layers
    out.extend(struct.pack("<iI", 0, 0))
    string("")
    string("cost")
    out.extend(b"\x00")  # U8
    u32(2)
    out.extend(bytes([254, 3]))
    u32(0)
    u32(0)
    out.extend(struct.pack("<iI", 0, 0))
    string("")
    string("height")
    out.extend(b"\x02")  # F64
    u32(0)
    u32(0)
    u32(2)
    pad(8)
    out.extend(struct.pack("<2d", 0.5, 1.5))
    out.extend(b"\x4e\x3f\x00\x00")  # trailing bytes, ignored
    return bytes(out)


def test_reads_bytes_built_from_the_message_definition(tmp_path):
    payload = _cdr_by_hand()
    path = tmp_path / "hand.navmap"
    path.write_bytes(b"NAVMAP\x00\x00" + struct.pack("<IQ", 1, len(payload)) + payload)
    navmap = load_navmap(path)
    assert navmap.frame_id == "odom"
    np.testing.assert_array_equal(navmap.faces, [[0, 1, 2], [1, 3, 2]])
    np.testing.assert_array_equal(navmap.vertices[:, 2], [0, 0, 1, 1])
    assert navmap.layer("cost").tolist() == [254, 3]
    assert navmap.layer("height").dtype == np.float64
    assert navmap.layer("height").tolist() == [0.5, 1.5]
    assert len(navmap.surfaces) == 1 and list(navmap.surfaces[0].navcels) == [0, 1]
    # Without the envelope: the whole file is the payload (the original's fallback).
    bare = tmp_path / "bare.navmap"
    bare.write_bytes(payload)
    assert load_navmap(bare).layer("cost").tolist() == [254, 3]
    # The payload alone, through the CDR reader.
    assert navmap_from_cdr(payload).num_navcels == 2


def test_real_navmap_file_if_available():
    """The ROSCon 2025 workshop's excavation_urjc.navmap (848 KB, not shipped here): set
    EASYNAV_NAVMAP_SAMPLE to its path to run this test."""
    sample = os.environ.get("EASYNAV_NAVMAP_SAMPLE")
    if not sample or not Path(sample).is_file():
        pytest.skip("EASYNAV_NAVMAP_SAMPLE not set")
    navmap = load_navmap(sample)
    assert navmap.num_vertices == 30209 and navmap.num_navcels == 30388
    assert navmap.list_layers() == ["elevation"]


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda raw: raw[:30], "payload"),
        (lambda raw: raw[:8] + struct.pack("<IQ", 2, 10) + raw[20:], "version 2"),
        (lambda raw: raw[:20] + b"\x07\x07" + raw[22:], "encapsulation"),
        (lambda raw: raw[:8] + struct.pack("<IQ", 1, len(raw) - 60) + raw[20:-40], "ends at"),
        (lambda raw: raw[:-40], "announces a"),
        (lambda raw: b"", "empty"),
    ],
)
def test_malformed_files_name_the_file(tmp_path, mutate, message):
    raw = save_navmap(small_map(), tmp_path / "ok.navmap").read_bytes()
    bad = tmp_path / "bad.navmap"
    bad.write_bytes(mutate(raw))
    with pytest.raises(MapFormatError, match=message) as info:
        load_navmap(bad)
    assert "bad.navmap" in str(info.value)


def test_missing_file():
    with pytest.raises(FileNotFoundError, match="nope.navmap"):
        load_navmap("/nonexistent/nope.navmap")


def test_bad_index_and_layer_size(tmp_path):
    navmap = NavMap([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    navmap.set_layer("x", np.zeros(1, np.uint8))
    raw = bytearray(save_navmap(navmap, tmp_path / "a.navmap").read_bytes())
    # navcels_v2 = [2] -> [9]
    idx = raw.rfind(struct.pack("<II", 1, 2))
    raw[idx + 4 : idx + 8] = struct.pack("<I", 9)
    (tmp_path / "b.navmap").write_bytes(bytes(raw))
    with pytest.raises(MapFormatError, match="vertex 9"):
        load_navmap(tmp_path / "b.navmap")


# -- builders -------------------------------------------------------------------------------------
def test_occupancy_to_u8_as_the_original():
    assert occupancy_to_u8(np.array([-1, 0, 1, 50, 99, 100], np.int8)).tolist() == [
        255, 0, 3, 127, 251, 254]


def test_from_occupancy_grid():
    data = np.array([[0, 100, -1], [0, 0, 50]], dtype=np.int8)  # 2 rows (y), 3 columns (x)
    grid = OccupancyGrid(Header(0.0, "map"), 0.5, Pose.from_xy_yaw(-1.0, 2.0), data)
    navmap = navmap_from_occupancy_grid(grid)
    assert navmap.num_vertices == 4 * 3 and navmap.num_navcels == 12
    occ = navmap.layer("occupancy")
    assert occ.tolist() == [0, 0, 254, 254, 255, 255, 0, 0, 0, 0, 127, 127]
    # cell (i=1, j=0) covers x in [-0.5, 0), y in [2, 2.5)
    assert navmap.locate_navcel((-0.25, 2.1, 0.0)) in (2, 3)
    assert navmap.locate_navcel((0.25, 2.9, 0.0)) in (10, 11)
    np.testing.assert_allclose(navmap.areas, 0.125)
    assert (navmap.normals[:, 2] > 0).all()
    with pytest.raises(ValueError, match="yaw"):
        navmap_from_occupancy_grid(OccupancyGrid(Header(), 0.5, Pose.from_xy_yaw(0, 0, 0.3), data))


def test_from_map_yaml(tmp_path):
    import cv2

    image = np.full((4, 5), 254, np.uint8)
    image[0, 0] = 0  # top-left pixel: occupied, the last row of the grid
    cv2.imwrite(str(tmp_path / "m.pgm"), image)
    (tmp_path / "m.yaml").write_text(
        "image: m.pgm\nresolution: 0.1\norigin: [1.0, 2.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    navmap = navmap_from_map_yaml(tmp_path / "m.yaml")
    occ = navmap.layer("occupancy")
    assert navmap.num_navcels == 40 and (occ == 254).sum() == 2
    assert navmap.layer_get("occupancy", navmap.locate_navcel((1.05, 2.35, 0))) == 254
    with pytest.raises(FileNotFoundError, match="nothere.yaml"):
        navmap_from_map_yaml(tmp_path / "nothere.yaml")


def test_from_points_delaunay():
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 5, size=(200, 2))
    points = np.column_stack([xy, 0.1 * xy[:, 0]])
    navmap = navmap_from_points(points)
    assert navmap.num_navcels > 300
    assert (navmap.normals[:, 2] > 0).all()
    cids, heights = navmap.locate(np.array([[2.5, 2.5, 3.0]]))
    assert cids[0] >= 0 and heights[0] == pytest.approx(0.25)
    short = navmap_from_points(points, max_edge_length=0.5)
    assert short.num_navcels < navmap.num_navcels
    with pytest.raises(ValueError, match="3 distinct"):
        navmap_from_points(np.zeros((5, 3)))


def test_from_obj_file(tmp_path):
    path = tmp_path / "quad.obj"
    path.write_text("# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0.5\nvn 0 0 1\n"
                    "f 1/1/1 2/2/1 3/3/1 4/4/1\n")
    navmap = navmap_from_mesh_file(path)
    assert navmap.faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    (tmp_path / "bad.obj").write_text("v 0 0 0\nf 1 x 2\n")
    with pytest.raises(MapFormatError, match="bad.obj:2"):
        navmap_from_mesh_file(tmp_path / "bad.obj")


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian", "binary_big_endian"])
def test_from_ply_file(tmp_path, fmt):
    verts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.5], [0, 1, 0.5]], np.float32)
    faces = [[0, 1, 2], [0, 2, 3]]
    header = (
        f"ply\nformat {fmt} 1.0\ncomment test\nelement vertex 4\nproperty float x\n"
        "property float y\nproperty float z\nproperty uchar red\nelement face 2\n"
        "property list uchar int vertex_indices\nend_header\n"
    ).encode()
    if fmt == "ascii":
        body = "".join(f"{x} {y} {z} 7\n" for x, y, z in verts)
        body += "".join(f"3 {a} {b} {c}\n" for a, b, c in faces)
        data = header + body.encode()
    else:
        o = "<" if "little" in fmt else ">"
        data = header + b"".join(struct.pack(o + "fffB", *v, 7) for v in verts)
        data += b"".join(struct.pack(o + "Biii", 3, *f) for f in faces)
    path = tmp_path / "m.ply"
    path.write_bytes(data)
    navmap = navmap_from_mesh_file(path)
    np.testing.assert_allclose(navmap.vertices, verts)
    assert navmap.faces.tolist() == faces
    path.write_bytes(data[:-6])
    if fmt != "ascii":
        with pytest.raises(MapFormatError, match="m.ply"):
            navmap_from_mesh_file(path)


def test_ply_polygon_faces_are_fanned(tmp_path):
    data = (b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\n"
            b"property double y\nproperty double z\nelement face 1\n"
            b"property list uchar uint vertex_indices\nend_header\n")
    data += struct.pack("<12d", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0)
    data += struct.pack("<B4I", 4, 0, 1, 2, 3)
    (tmp_path / "q.ply").write_bytes(data)
    assert navmap_from_mesh_file(tmp_path / "q.ply").faces.tolist() == [[0, 1, 2], [0, 2, 3]]


def test_mesh_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="x.ply"):
        navmap_from_mesh_file(tmp_path / "x.ply")
    (tmp_path / "x.stl").write_text("solid")
    with pytest.raises(MapFormatError, match="x.stl"):
        navmap_from_mesh_file(tmp_path / "x.stl")
    (tmp_path / "p.ply").write_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                    "end_header\n0\n")
    with pytest.raises(MapFormatError, match="face"):
        navmap_from_mesh_file(tmp_path / "p.ply")


def test_surfaces_kept(tmp_path):
    verts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 1], [6, 5, 1], [5, 6, 1]], float)
    navmap = NavMap(verts, [[0, 1, 2], [3, 4, 5]],
                    surfaces=[Surface("a", [0]), Surface("b", [1])])
    back = load_navmap(save_navmap(navmap, tmp_path / "s.navmap"))
    assert [(s.frame_id, s.navcels.tolist()) for s in back.surfaces] == [("a", [0]), ("b", [1])]
