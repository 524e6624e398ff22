"""GridMap, its slope layer, its files (the original's YAML + PGM, our .npz) and the manager."""

from __future__ import annotations

import itertools
import math

import cv2
import numpy as np
import pytest
import yaml

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.maps.gridmap import (
    GridMap,
    load_gridmap,
    save_gridmap_npz,
    save_gridmap_yaml,
    slope_layer,
)
from easynav.maps.gridmap.gridmap_maps_manager import GridmapMapsManager
from easynav.maps.map_format_error import MapFormatError

_namespaces = itertools.count()


def cell_centres(shape, resolution, origin=(0.0, 0.0)):
    h, w = shape
    xs = origin[0] + (np.arange(w) + 0.5) * resolution
    ys = origin[1] + (np.arange(h) + 0.5) * resolution
    return np.meshgrid(xs, ys)


@pytest.mark.parametrize(("a", "b"), [(0.5, 0.0), (0.0, -1.2), (0.3, 0.4)])
def test_slope_of_a_ramp_is_its_angle_everywhere(a, b):
    x, y = cell_centres((30, 40), 0.1)
    slope = slope_layer(a * x + b * y + 2.0, 0.1)
    np.testing.assert_allclose(slope, math.atan(math.hypot(a, b)), atol=1e-12)


def test_slope_of_a_cone_matches_the_direct_gradient_away_from_the_apex():
    resolution, k = 0.05, 0.7
    x, y = cell_centres((81, 81), resolution, origin=(-2.025, -2.025))
    r = np.hypot(x, y)
    slope = slope_layer(k * r, resolution)
    # Direct: grad(k r) = k (x, y) / r, so |grad| = k away from the apex.
    far = r >= 5 * resolution
    np.testing.assert_allclose(np.tan(slope[far]), k, rtol=0.01)
    assert np.tan(slope[40, 40]) < k  # the apex: central differences straddle the tip


def test_unknown_height_makes_its_neighbours_slope_unknown():
    z = np.zeros((5, 5))
    z[2, 2] = np.nan
    slope = slope_layer(z, 0.1)
    assert np.isnan(slope[2, 1]) and np.isnan(slope[1, 2]) and np.isnan(slope[2, 2])
    assert slope[0, 0] == 0.0


def test_from_elevation_derives_traversability():
    x, _ = cell_centres((10, 10), 0.1)
    grid = GridMap.from_elevation(math.tan(math.radians(15)) * x, 0.1,
                                  max_slope_rad=math.radians(30))
    np.testing.assert_allclose(grid.layer("traversability"), 0.5, atol=1e-9)
    with pytest.raises(KeyError, match="layers"):
        grid.layer("colour")


def write_original_map(directory, image, low, high, resolution=0.5, position=(1.0, -1.0)):
    """A gridmap file exactly as the original's save_gridmap writes it."""
    nx, ny = image.shape  # grid_map: rows along -x, columns along -y
    doc = {
        "layers": [{"name": "elevation", "min": low, "max": high}],
        "resolution": resolution,
        "length": [nx * resolution, ny * resolution],
        "position": list(position),
    }
    path = directory / "terrain.yaml"
    path.write_text(yaml.safe_dump(doc))
    cv2.imwrite(str(directory / "terrain_elevation.pgm"), image)
    return path


def test_the_originals_map_file_loads_with_grid_maps_orientation(tmp_path):
    image = np.zeros((4, 6), np.uint8)  # 4 cells along x, 6 along y
    image[0, :] = 255  # row 0: the +x edge
    image[:, 0] = 51  # column 0: the +y edge (0.2 of the range)
    image[0, 0] = 255
    grid = load_gridmap(write_original_map(tmp_path, image, -1.0, 4.0))
    assert grid.shape == (6, 4)
    assert grid.resolution == 0.5
    assert (grid.origin_x, grid.origin_y) == (0.0, -2.5)  # centre (1, -1), 2 m x 3 m
    z = grid.elevation
    np.testing.assert_allclose(z[:, 3], 4.0)  # +x column
    np.testing.assert_allclose(z[5, :3], 0.0)  # +y row: -1 + 5 * 0.2
    np.testing.assert_allclose(z[:5, :3], -1.0)
    assert set(grid.layers) == {"elevation", "slope", "traversability"}
    # World lookups agree: the +x, +y corner cell.
    ix, iy = grid.world_to_cell(1.9, 0.4)
    assert z[iy, ix] == 4.0


def test_original_format_round_trip_within_quantisation(tmp_path):
    x, y = cell_centres((12, 20), 0.25, origin=(-3.0, 2.0))
    z = 0.1 * x - 0.05 * y + np.sin(x)
    path = save_gridmap_yaml(GridMap.from_elevation(z, 0.25, -3.0, 2.0), tmp_path / "m.yaml")
    loaded = load_gridmap(path)
    assert (loaded.origin_x, loaded.origin_y, loaded.shape) == (-3.0, 2.0, (12, 20))
    np.testing.assert_allclose(loaded.elevation, z, atol=(z.max() - z.min()) / 255 / 2 + 1e-9)


def test_npz_round_trip_is_exact_and_keeps_unknown(tmp_path):
    z = np.random.default_rng(1).normal(size=(7, 9))
    z[3, 4] = np.nan
    grid = GridMap.from_elevation(z, 0.2, 1.5, -0.5)
    grid.layers["friction"] = np.ones_like(z)
    loaded = load_gridmap(save_gridmap_npz(grid, tmp_path / "m.npz"))
    np.testing.assert_array_equal(loaded.elevation, z)
    assert loaded.origin_x == 1.5 and loaded.origin_y == -0.5 and loaded.resolution == 0.2
    assert "friction" in loaded.layers


def test_bad_files_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere.yaml"):
        load_gridmap(tmp_path / "nowhere.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("layers: [{name: elevation, min: 0, max: 1}]\nresolution: 0.1\n")
    with pytest.raises(MapFormatError, match="length"):
        load_gridmap(bad)
    image = np.zeros((4, 6), np.uint8)
    path = write_original_map(tmp_path, image, 0.0, 1.0)
    path.write_text(path.read_text().replace("- 2.0", "- 2.5"))  # length no longer matches
    with pytest.raises(MapFormatError, match="terrain_elevation.pgm"):
        load_gridmap(path)
    (tmp_path / "terrain_elevation.pgm").unlink()
    with pytest.raises(FileNotFoundError, match="terrain_elevation.pgm"):
        load_gridmap(path)


def make_manager(params) -> GridmapMapsManager:
    manager = GridmapMapsManager()
    manager.initialize(
        PluginContext(
            parameters=DictParameters({f"gm.{k}": v for k, v in params.items()}),
            namespace=f"gridmap_test_{next(_namespaces)}",
            now=lambda: 1.0,
        ),
        "gm",
    )
    return manager


def test_manager_writes_the_map_under_the_originals_key(tmp_path):
    x, _ = cell_centres((10, 10), 0.1)
    path = save_gridmap_npz(GridMap.from_elevation(0.2 * x, 0.1), tmp_path / "m.npz")
    manager = make_manager({"map_path_file": str(path)})
    assert GridmapMapsManager.PROVIDES_MAPS == ("gridmap",)
    nav_state = NavState()
    manager.update(nav_state)
    grid = nav_state.get("map")
    assert isinstance(grid, GridMap)
    np.testing.assert_allclose(grid.layer("slope"), math.atan(0.2), atol=1e-12)


def test_manager_reports_a_missing_map_naming_it(tmp_path):
    with pytest.raises(PluginConfigurationError, match="gm.package / gm.map_path_file.*gone"):
        make_manager({"map_path_file": str(tmp_path / "gone.yaml")})


def test_set_map_replaces_the_map_with_its_layers_derived(tmp_path):
    x, _ = cell_centres((10, 10), 0.1)
    path = save_gridmap_npz(GridMap.from_elevation(np.tan(math.radians(10)) * x, 0.1),
                            tmp_path / "m.npz")
    manager = make_manager({"map_path_file": str(path)})
    nav_state = NavState()
    manager.update(nav_state)
    np.testing.assert_allclose(nav_state.get("map").layer("traversability"), 2 / 3, atol=1e-9)
    manager.set_map(GridMap(0.1, 0.0, 0.0, {"elevation": np.zeros((4, 4))}))
    manager.update(nav_state)
    assert nav_state.get("map").shape == (4, 4)
    np.testing.assert_allclose(nav_state.get("map").layer("slope"), 0.0)
    with pytest.raises(TypeError, match="GridMap"):
        manager.set_map(np.zeros((3, 3)))
