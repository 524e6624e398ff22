"""KeepoutFilter and SpeedFilter from mask maps (Nav2-style costmap filters), without ROS."""

from __future__ import annotations

import itertools

import cv2
import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import Costmap2D, Header, Odometry, Pose
from easynav.maps.costmap import MAP, MAP_OBSTACLE_BOUNDS, SPEED_LIMIT
from easynav.maps.costmap.costmap_maps_manager import CostmapMapsManager
from easynav.maps.costmap.filter_mask import FilterMask
from easynav.maps.costmap.speed_filter import speed_limit_fraction
from easynav.maps.inflation import inflate

_namespaces = itertools.count()
PREFIX = "easynav_costmap_maps_manager/CostmapMapsManager/"


def free_map(tmp_path, size=40, resolution=0.1):
    cv2.imwrite(str(tmp_path / "free.pgm"), np.full((size, size), 254, np.uint8))
    (tmp_path / "free.yaml").write_text(
        f"image: free.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return tmp_path / "free.yaml"


def mask(tmp_path, name, pixels, resolution=0.1, origin=(0.0, 0.0), mode="trinary"):
    cv2.imwrite(str(tmp_path / f"{name}.png"), pixels)
    (tmp_path / f"{name}.yaml").write_text(
        f"image: {name}.png\nresolution: {resolution}\norigin: [{origin[0]}, {origin[1]}, 0.0]\n"
        f"negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: {mode}\n"
    )
    return tmp_path / f"{name}.yaml"


def manager(params, limits=None):
    context = PluginContext(
        parameters=DictParameters({f"costmap.{k}": v for k, v in params.items()}),
        namespace=f"zones_{next(_namespaces)}",
        now=lambda: 10.0,
        robot_limits=(lambda: limits) if limits else RobotLimits,
    )
    m = CostmapMapsManager()
    m.initialize(context, "costmap")
    return m


def keepout_mask(tmp_path):
    # 20x20 mask at 0.1 m: a black 4x4 block (keepout) at image rows 2..5, cols 10..13.
    pixels = np.full((20, 20), 254, np.uint8)
    pixels[2:6, 10:14] = 0
    return mask(tmp_path, "keepout", pixels)


def test_keepout_cells_become_lethal_even_over_unknown(tmp_path):
    params = {
        "map_path_file": str(free_map(tmp_path)),
        "filters": ["keepout"],
        "keepout.plugin": PREFIX + "KeepoutFilter",
        "keepout.mask_path_file": str(keepout_mask(tmp_path)),
    }
    m = manager(params)
    nav_state = NavState()
    m.update(nav_state)
    live = nav_state.get(MAP, Costmap2D)
    # Image rows 2..5 of a 20-row mask are map rows 14..17.
    expected = np.zeros((40, 40), bool)
    expected[14:18, 10:14] = True
    assert np.array_equal(live.data == 254, expected)
    assert (m.base_map.data == 0).all()  # the static map is untouched
    x0, y0, x1, y1 = nav_state.get(MAP_OBSTACLE_BOUNDS)
    assert (x0, y0, x1, y1) == pytest.approx((1.05, 1.45, 1.35, 1.75))
    # Over unknown space too.
    unknown = Costmap2D.filled(40, 40, 0.1, value=255)
    unknown.stamp = 99.0
    nav_state.set("map.base", unknown)
    m.update(nav_state)
    assert np.array_equal(nav_state.get(MAP).data == 254, expected)


def test_keepout_before_inflation_keeps_the_body_out(tmp_path):
    params = {
        "map_path_file": str(free_map(tmp_path)),
        "filters": ["keepout", "inflation"],
        "keepout.plugin": PREFIX + "KeepoutFilter",
        "keepout.mask_path_file": str(keepout_mask(tmp_path)),
        "inflation.plugin": PREFIX + "InflationFilter",
        "inflation.inflation_radius": 0.5,
    }
    m = manager(params)
    nav_state = NavState()
    m.update(nav_state)
    marked = np.zeros((40, 40), np.uint8)
    marked[14:18, 10:14] = 254
    assert np.array_equal(nav_state.get(MAP).data, inflate(marked, 0.1, 0.5, 0.3, 3.0))
    # Disabled at runtime: nothing.
    m.apply_parameter("keepout.enabled", False)
    m.update(nav_state)
    assert (nav_state.get(MAP).data == 0).all()


def test_mask_with_its_own_resolution_and_origin(tmp_path):
    pixels = np.full((4, 4), 254, np.uint8)
    pixels[3, 0] = 0  # the mask's bottom-left 0.2 m cell, at world (1.0..1.2, 1.0..1.2)
    path = mask(tmp_path, "coarse", pixels, resolution=0.2, origin=(1.0, 1.0))
    grid = Costmap2D.filled(40, 40, 0.1)
    values = FilterMask.load("", str(path)).values_on(grid)
    assert values[10:12, 10:12].tolist() == [[100, 100], [100, 100]]
    assert values[9, 10] == -1 and values[12, 12] == 0 and values[30, 30] == -1


def test_graded_keepout_values_raise_costs(tmp_path):
    pixels = np.full((1, 3), 254, np.uint8)
    pixels[0, 1] = 150
    path = mask(tmp_path, "grey", pixels, mode="scale")
    params = {
        "map_path_file": str(free_map(tmp_path, size=3)),
        "filters": ["keepout"],
        "keepout.plugin": PREFIX + "KeepoutFilter",
        "keepout.mask_path_file": str(path),
    }
    nav_state = NavState()
    manager(params).update(nav_state)
    row = nav_state.get(MAP).data[0]
    assert row[0] == 0 and 0 < row[1] < 253 and row[2] == 0


def test_speed_limit_fraction_rules():
    assert speed_limit_fraction(0, "percent", 0.0, 1.0, 0.5) == 1.0
    assert speed_limit_fraction(-1, "percent", 0.0, 1.0, 0.5) == 1.0
    assert speed_limit_fraction(40, "percent", 0.0, 1.0, 0.5) == pytest.approx(0.4)
    assert speed_limit_fraction(40, "percent", 10.0, 0.5, 0.5) == pytest.approx(0.3)
    assert speed_limit_fraction(100, "percent", 50.0, 1.0, 0.5) == 1.0
    assert speed_limit_fraction(20, "absolute", 0.0, 0.01, 0.5) == pytest.approx(0.4)
    assert speed_limit_fraction(20, "absolute", -1.0, 0.01, 0.5) == 1.0  # limit <= 0: none


def test_speed_zone_under_the_robot(tmp_path):
    pixels = np.full((40, 40), 254, np.uint8)
    pixels[:, 20:] = 153  # right half: grey, 40 % occupancy in scale mode
    path = mask(tmp_path, "speed", pixels, mode="scale")
    params = {
        "map_path_file": str(free_map(tmp_path)),
        "filters": ["speed"],
        "speed.plugin": PREFIX + "SpeedFilter",
        "speed.mask_path_file": str(path),
    }
    m = manager(params)
    nav_state = NavState()
    m.update(nav_state)
    assert not nav_state.has(SPEED_LIMIT)  # pose unknown: nothing said
    nav_state.set("robot_pose", Odometry(Header(10.0, "map"), "base", Pose.from_xy_yaw(1.0, 2.0)))
    m.update(nav_state)
    assert nav_state.get(SPEED_LIMIT) == 1.0
    nav_state.set("robot_pose", Odometry(Header(10.0, "map"), "base", Pose.from_xy_yaw(3.0, 2.0)))
    m.update(nav_state)
    value = FilterMask.load("", str(path)).value_at(3.0, 2.0)
    assert 0 < value < 100
    assert nav_state.get(SPEED_LIMIT) == pytest.approx(value / 100.0)
    assert (nav_state.get(MAP).data == 0).all()  # the costmap is not changed
    m.apply_parameter("speed.type", "absolute")
    m.apply_parameter("speed.multiplier", 0.005)
    m.update(nav_state)
    assert nav_state.get(SPEED_LIMIT) == pytest.approx(min(1.0, value * 0.005 / 0.5))


@pytest.mark.parametrize("plugin", ["KeepoutFilter", "SpeedFilter"])
def test_missing_mask_fails_configure(tmp_path, plugin):
    params = {
        "map_path_file": str(free_map(tmp_path)), "filters": ["z"], "z.plugin": PREFIX + plugin
    }
    with pytest.raises(PluginConfigurationError, match="costmap.z.mask_path_file is empty"):
        manager(params)
    params["z.mask_path_file"] = str(tmp_path / "nope.yaml")
    with pytest.raises(PluginConfigurationError, match="costmap.z.mask_path_file: .*nope.yaml"):
        manager(params)
