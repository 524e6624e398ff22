"""Costmap2D from map_server files and occupancy grids, and back, with the original EasyNav's
conversions: occupancy -1 -> 255 (unknown), else round(v·254/100); back, 255 -> -1 and every
other cost copied as is."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from easynav.core.types import Costmap2D, Header, Pose
from easynav.maps import MapFormatError, OccupancyGrid, load_map_yaml
from easynav.maps.costmap_io import (
    costmap_from_occupancy_grid,
    costmap_to_occupancy_grid,
    costs_to_occupancy_message,
    costs_to_occupancy_percent,
    load_costmap_yaml,
    occupancy_to_costs,
    save_costmap_yaml,
)

SHARED_MAPS = Path("/work/shared/maps")


def write_map(tmp_path, pixels, name="m", **keys) -> Path:
    cv2.imwrite(str(tmp_path / f"{name}.png"), pixels)
    doc = {
        "image": f"{name}.png",
        "resolution": 0.1,
        "origin": "[1.0, -2.0, 0.0]",
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    doc.update(keys)
    (tmp_path / f"{name}.yaml").write_text("".join(f"{k}: {v}\n" for k, v in doc.items()))
    return tmp_path / f"{name}.yaml"


def test_occupancy_to_cost_follows_the_original():
    values = np.array([-1, 0, 25, 50, 65, 75, 99, 100, -2, -3, 120], dtype=np.int8)
    costs = occupancy_to_costs(values)
    # round(v * 254 / 100) with halves up: 25 -> 63.5 -> 64, 75 -> 190.5 -> 191.
    assert costs.tolist() == [255, 0, 64, 127, 165, 191, 251, 254, 254, 253, 120]
    for v in range(101):
        assert occupancy_to_costs(np.array([v], dtype=np.int8))[0] == int(v * 254 / 100 + 0.5)


def test_cost_to_message_copies_bytes_and_unknown_is_minus_one():
    costs = np.array([0, 100, 101, 252, 253, 254, 255], dtype=np.uint8)
    assert costs_to_occupancy_message(costs).tolist() == [0, 100, 101, -4, -3, -2, -1]
    # Bytes outside 0..100 read back as the same costs (0..100 are occupancy percent).
    high = np.array([101, 252, 253, 254, 255], dtype=np.uint8)
    assert occupancy_to_costs(costs_to_occupancy_message(high)).tolist() == high.tolist()


def test_cost_to_percent_inverts_the_load_conversion():
    percent = np.arange(-1, 101, dtype=np.int8)
    assert costs_to_occupancy_percent(occupancy_to_costs(percent)).tolist() == percent.tolist()


def test_trinary_scale_raw_and_negate_on_hand_made_images(tmp_path):
    pixels = np.array([[0, 255, 205], [255, 255, 0]], dtype=np.uint8)
    costmap = load_costmap_yaml(write_map(tmp_path, pixels))
    # Image top row = map's last row; black lethal, white free, 205 unknown.
    assert costmap.data.tolist() == [[0, 0, 254], [254, 0, 255]]
    assert (costmap.origin_x, costmap.origin_y, costmap.resolution) == (1.0, -2.0, 0.1)
    assert costmap.cost_at(1.05, -1.95) == 0 and costmap.cost_at(1.25, -1.95) == 254
    negated = load_costmap_yaml(write_map(tmp_path, pixels, name="n", negate=1))
    # Negated, the grey 205 (shade 0.80) is above occupied_thresh.
    assert negated.data.tolist() == [[254, 254, 0], [0, 254, 254]]
    raw = load_costmap_yaml(
        write_map(tmp_path, np.array([[0, 50, 100, 150]], np.uint8), name="r", mode="raw")
    )
    assert raw.data.tolist() == [[0, 127, 254, 255]]
    grey = np.array([[255, 150, 0]], dtype=np.uint8)
    scale = load_costmap_yaml(write_map(tmp_path, grey, name="s", mode="scale"))
    occ = 1.0 - 150 / 255.0
    percent = round(99 * (occ - 0.196) / (0.65 - 0.196))
    assert scale.data.tolist() == [[0, int(percent * 254 / 100 + 0.5), 254]]


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"occupied_threshold": 0.6}, "unknown key.*'occupied_threshold'"),
        ({"origin": "[0, 0, 0.5]"}, "yaw"),
        ({"image": "missing.png"}, "map image not found: .*missing.png"),
        ({"resolution": -1}, "'resolution' must be > 0"),
    ],
)
def test_bad_maps_get_clear_errors(tmp_path, keys, message):
    path = write_map(tmp_path, np.zeros((2, 2), np.uint8), **keys)
    with pytest.raises((MapFormatError, FileNotFoundError), match=message):
        load_costmap_yaml(path)


def test_unreadable_image_is_named(tmp_path):
    path = write_map(tmp_path, np.zeros((2, 2), np.uint8))
    (tmp_path / "m.png").write_bytes(b"not a png")
    with pytest.raises(MapFormatError, match="m.png"):
        load_costmap_yaml(path)


def test_save_writes_trinary_pgm_that_loads_back(tmp_path):
    data = np.array([[0, 64, 100, 165], [200, 253, 254, 255]], dtype=np.uint8)
    costmap = Costmap2D(data, 0.05, -3.0, 4.5)
    yaml_path, image_path = save_costmap_yaml(costmap, tmp_path / "out" / "saved.yaml")
    assert image_path == tmp_path / "out" / "saved.pgm" and image_path.read_bytes()[:2] == b"P5"
    pixels = cv2.imread(str(image_path), cv2.IMREAD_UNCHANGED)
    # Row order flipped; percent <= 25 free (254), >= 65 occupied (0), else unknown (205).
    assert pixels.tolist() == [[0, 0, 0, 205], [254, 254, 205, 0]]
    loaded = load_costmap_yaml(yaml_path)
    assert loaded.data.tolist() == [[0, 0, 255, 254], [254, 254, 254, 255]]
    assert (loaded.origin_x, loaded.origin_y, loaded.resolution) == (-3.0, 4.5, 0.05)


def test_occupancy_grid_round_trip_keeps_frame_stamp_origin():
    grid = OccupancyGrid(
        Header(12.5, "world"), 0.2, Pose.from_xy_yaw(1.0, 2.0), np.array([[0, 100, -1]], np.int8)
    )
    costmap = costmap_from_occupancy_grid(grid)
    assert (costmap.frame_id, costmap.stamp, costmap.origin_x, costmap.origin_y) == (
        "world", 12.5, 1.0, 2.0,
    )
    back = costmap_to_occupancy_grid(costmap)
    assert back.data.tolist() == [[0, -2, -1]] and back.header.frame_id == "world"
    assert costmap_to_occupancy_grid(costmap, percent=True).data.tolist() == [[0, 100, -1]]
    with pytest.raises(ValueError, match="yaw"):
        costmap_from_occupancy_grid(
            OccupancyGrid(Header(), 0.2, Pose.from_xy_yaw(0, 0, 0.3), grid.data)
        )


@pytest.mark.skipif(not SHARED_MAPS.is_dir(), reason="shared real maps not present")
@pytest.mark.parametrize("name", ["tb3_sandbox", "depot", "warehouse"])
def test_real_maps_load(name):
    costmap = load_costmap_yaml(SHARED_MAPS / f"{name}.yaml")
    grid = load_map_yaml(SHARED_MAPS / f"{name}.yaml")
    assert costmap.data.shape == grid.data.shape
    assert set(np.unique(costmap.data).tolist()) <= {0, 254, 255}
    assert (costmap.data == 254).sum() == (grid.data == 100).sum() > 0
