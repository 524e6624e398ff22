"""Finding map files from `package` + `map_path_file`."""

from __future__ import annotations

import pytest

from easynav.maps import SimpleMap, resolve_map_file


def test_package_by_map_package_entry_point_distribution_or_module_name():
    expected = resolve_map_file("easynav_maps", "worlds/home.map")
    assert expected.name == "home.map" and expected.is_file()
    assert resolve_map_file("easynav-maps", "worlds/home.map") == expected
    assert resolve_map_file("easynav.maps", "worlds/home.map") == expected


def test_plain_path_when_package_is_empty(tmp_path, monkeypatch):
    SimpleMap(2, 2, 0.1).save(tmp_path / "mine.map")
    assert resolve_map_file("", str(tmp_path / "mine.map")) == tmp_path / "mine.map"
    monkeypatch.chdir(tmp_path)
    assert resolve_map_file("", "mine.map") == tmp_path / "mine.map"


def test_missing_file_and_package_are_named():
    with pytest.raises(FileNotFoundError, match="'worlds/castle.map' of package 'easynav_maps'"):
        resolve_map_file("easynav_maps", "worlds/castle.map")
    with pytest.raises(FileNotFoundError, match="package 'no_such_package'"):
        resolve_map_file("no_such_package", "maps/home.map")
    with pytest.raises(FileNotFoundError, match="map file not found: nowhere.map"):
        resolve_map_file("", "nowhere.map")


def test_paths_escaping_the_package_are_refused():
    with pytest.raises(ValueError, match="relative path inside package"):
        resolve_map_file("easynav_maps", "../../etc/passwd")
    with pytest.raises(ValueError, match="map_path_file is empty"):
        resolve_map_file("easynav_maps", "")


def test_share_prefix_layout_of_ros_style_packages(tmp_path, monkeypatch):
    share = tmp_path / "share" / "my_robot_maps" / "maps"
    share.mkdir(parents=True)
    SimpleMap(3, 3, 0.1).save(share / "lab.map")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    assert resolve_map_file("my_robot_maps", "maps/lab.map") == share / "lab.map"
