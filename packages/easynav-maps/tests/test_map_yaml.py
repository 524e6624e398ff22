"""Loading ROS map_server maps (YAML + image) with map_server semantics."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from easynav.maps import MapFormatError, SimpleMap, load_map_yaml

SHARED_MAPS = Path("/work/shared/maps")


def write_map(tmp_path, pixels, **keys) -> Path:
    cv2.imwrite(str(tmp_path / "m.png"), pixels)
    doc = {
        "image": "m.png",
        "resolution": 0.1,
        "origin": "[1.0, -2.0, 0.0]",
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    doc.update({k: v for k, v in keys.items() if v is not None})
    for k in [k for k, v in keys.items() if v is None]:
        doc.pop(k)
    text = "".join(f"{k}: {v}\n" for k, v in doc.items())
    (tmp_path / "m.yaml").write_text(text)
    return tmp_path / "m.yaml"


# Grey levels: black (occupied), white (free), mid grey (unknown in trinary).
PIXELS = np.array([[0, 255, 128], [255, 255, 0]], dtype=np.uint8)


def test_trinary_map_flips_rows_and_thresholds(tmp_path):
    grid = load_map_yaml(write_map(tmp_path, PIXELS))
    # The image's top row is the map's last row.
    assert grid.data.tolist() == [[0, 0, 100], [100, 0, -1]]
    assert (grid.origin.x, grid.origin.y, grid.resolution) == (1.0, -2.0, 0.1)
    world = SimpleMap.from_map_yaml(tmp_path / "m.yaml")
    assert world.occupied_at(1.05, -1.85) and not world.occupied_at(1.15, -1.85)
    assert world.occupied_at(1.25, -1.85 + 0.1 * 0)  # (x=2, y=0) is black
    assert SimpleMap.load(tmp_path / "m.yaml") == world  # .yaml dispatches to the map loader


def test_negate_swaps_black_and_white(tmp_path):
    grid = load_map_yaml(write_map(tmp_path, PIXELS, negate=1))
    assert grid.data.tolist() == [[100, 100, 0], [0, 100, -1]]


def test_scale_mode_grades_between_thresholds_and_alpha_is_unknown(tmp_path):
    rgba = np.zeros((1, 3, 4), dtype=np.uint8)
    rgba[0, :, :3] = np.array([255, 150, 150])[:, None]  # free, graded, graded
    rgba[0, :, 3] = [255, 255, 100]  # the last pixel is not opaque
    grid = load_map_yaml(write_map(tmp_path, rgba, mode="scale"))
    occ = 1.0 - 150 / 255.0
    graded = round(99 * (occ - 0.196) / (0.65 - 0.196))
    assert grid.data.tolist() == [[0, graded, -1]]


def test_raw_mode_keeps_values_up_to_100(tmp_path):
    pixels = np.array([[0, 57, 100, 101, 255]], dtype=np.uint8)
    grid = load_map_yaml(write_map(tmp_path, pixels, mode="raw"))
    assert grid.data.tolist() == [[0, 57, 100, -1, -1]]


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"resolution": None}, "'resolution' is missing"),
        ({"resolution": "fast"}, "'resolution' must be a number"),
        ({"origin": "[0, 0]"}, "'origin' must be"),
        ({"mode": "fancy"}, "'mode' must be one of"),
        ({"free_thresh": 0.9}, "thresholds"),
        ({"image": "other.png"}, "map image not found: .*other.png"),
    ],
)
def test_bad_yaml_names_file_and_key(tmp_path, keys, message):
    path = write_map(tmp_path, PIXELS, **keys)
    with pytest.raises((MapFormatError, FileNotFoundError), match=message):
        load_map_yaml(path)


def test_rotated_origin_is_refused_for_a_simple_map(tmp_path):
    path = write_map(tmp_path, PIXELS, origin="[0.0, 0.0, 0.5]")
    assert load_map_yaml(path).origin.yaw == pytest.approx(0.5)
    with pytest.raises(MapFormatError, match="m.yaml: .*rotated"):
        SimpleMap.from_map_yaml(path)


@pytest.mark.skipif(not SHARED_MAPS.is_dir(), reason="shared Nav2 maps not present")
def test_real_nav2_map_loads_with_its_free_space():
    world = SimpleMap.from_map_yaml(SHARED_MAPS / "tb3_sandbox.yaml")
    assert (world.width, world.height, world.resolution) == (384, 384, 0.05)
    assert (world.origin_x, world.origin_y) == (-10.0, -10.0)
    free = ~world.cells
    assert 0.02 < free.mean() < 0.2  # the sandbox's free area inside unknown surroundings
    assert not world.occupied_at(-2.0, -0.5)  # TurtleBot3's spawn point in the sandbox


@pytest.mark.parametrize(
    "header",
    [b"P5\n7 5\n255\n", b"P5 7 5 255 ", b"P5\n# CREATOR: map_saver\n7 5\n# x\n255\n",
     b"P5\t7\r\n5\n255\r"],
)
def test_binary_pgm_is_read_without_opencv_as_opencv_reads_it(tmp_path, header):
    from easynav.maps.map_yaml import read_pgm

    pixels = np.random.default_rng(len(header)).integers(0, 256, (5, 7), dtype=np.uint8)
    path = tmp_path / "m.pgm"
    path.write_bytes(header + pixels.tobytes())
    image = read_pgm(path)
    assert image.dtype == np.uint8 and np.array_equal(image, pixels)
    assert np.array_equal(image, cv2.imread(str(path), cv2.IMREAD_UNCHANGED))


@pytest.mark.parametrize(
    "content",
    [b"P5\n7 5\n65535\n" + bytes(70), b"P5\n7 5\n100\n" + bytes(35), b"P5\n7 5\n255\n" + bytes(3),
     b"P2\n2 1\n255\n0 1\n", b"\x89PNG\r\n"],
)
def test_other_images_are_left_to_opencv(tmp_path, content):
    from easynav.maps.map_yaml import read_pgm

    path = tmp_path / "m.pgm"
    path.write_bytes(content)
    assert read_pgm(path) is None


def test_a_map_saved_and_loaded_again_reads_the_same_pgm(tmp_path):
    from easynav.maps.map_yaml import read_pgm

    pixels = np.random.default_rng(3).integers(0, 256, (30, 41), dtype=np.uint8)
    cv2.imwrite(str(tmp_path / "w.pgm"), pixels)
    assert np.array_equal(read_pgm(tmp_path / "w.pgm"), pixels)
