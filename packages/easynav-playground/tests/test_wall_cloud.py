"""The wall cloud of the two_floors world (issue #17): the 3D map the NavMap stack's Bonxai
manager loads and its AMCL scores scans on. Regenerating it gives the committed file; its points
lie just off the surfaces the laser sees, in the voxel where a hit on them lands."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.playground.sim.multilevel import MultiLevelWorld
from easynav.playground.sim.wall_cloud import (
    ply_text,
    wall_cloud,
    wall_cloud_path,
    write_wall_cloud,
)
from easynav.playground.world_description import WORLDS_DIR

DESCRIPTION = WORLDS_DIR / "two_floors.yaml"


@pytest.fixture(scope="module")
def levels() -> MultiLevelWorld:
    return MultiLevelWorld.from_description_file(DESCRIPTION)


@pytest.fixture(scope="module")
def cloud(levels) -> np.ndarray:
    return wall_cloud(levels)


def test_regenerating_gives_the_committed_file(tmp_path):
    shipped = wall_cloud_path(DESCRIPTION)
    assert shipped.name == "two_floors.walls.ply"
    out = write_wall_cloud(DESCRIPTION, tmp_path / "walls.ply")
    assert out.read_text() == shipped.read_text()


def test_the_maps_manager_reader_reads_it(cloud):
    from easynav.maps.voxel.voxel_sources import read_point_cloud

    points = read_point_cloud(wall_cloud_path(DESCRIPTION))
    np.testing.assert_allclose(points, cloud, atol=1e-6)


def test_points_are_inside_the_bounds_and_not_inside_a_solid(levels, cloud):
    x0, y0, x1, y1 = levels.bounds
    assert (cloud[:, 0] >= x0).all() and (cloud[:, 0] <= x1).all()
    assert (cloud[:, 1] >= y0).all() and (cloud[:, 1] <= y1).all()
    for s in levels.solids:
        inside = ((cloud[:, 0] > s.x0) & (cloud[:, 0] < s.x1) & (cloud[:, 1] > s.y0)
                  & (cloud[:, 1] < s.y1) & (cloud[:, 2] > s.z0) & (cloud[:, 2] < s.z1))
        assert not inside.any(), s.name
    assert len(np.unique(cloud, axis=0)) == len(cloud)


def _near(cloud, x, y, z, tol=0.06):
    return bool((np.abs(cloud - (x, y, z)) <= tol).all(axis=1).any())


def test_what_each_level_s_laser_sees_is_in_the_cloud(cloud):
    # Ground floor, laser at 0.25 m: the partition's east face (x 3.1), the crate's west face.
    assert _near(cloud, 3.11, 1.25, 0.25)
    assert _near(cloud, 6.89, 4.85, 0.25)
    # Upper floor, laser at 1.75 m: the south railing's north face (y 3.6), the shelf.
    assert _near(cloud, 6.45, 3.61, 1.75)
    assert _near(cloud, 7.29, 5.55, 1.75)
    # The ramp's surface (1.5 (x - 1) / 4 at x = 3), just above it.
    assert _near(cloud, 3.05, 5.45, 1.5 * 2.05 / 4.0 + 0.01, tol=0.03)
    # The north wall's inner face at the upper floor's laser height; not its outer face.
    assert _near(cloud, 6.05, 5.89, 1.75)
    assert not (cloud[:, 1] > 6.0).any()


def test_points_are_one_centimetre_off_their_face(levels):
    room = MultiLevelWorld([levels.floors[0]], [], [levels.solids[4]], 0.05, levels.bounds,
                           name="partition only")
    pts = wall_cloud(room, spacing=0.5, offset=0.01)
    east = pts[np.isclose(pts[:, 0], 3.11) & (pts[:, 2] > 0.0)]
    assert len(east) > 0
    assert np.isclose(pts[:, 0], 3.1).sum() == 0  # nothing on the face itself
    # 0.5 m spacing over the 2.4 m x 2.5 m face: 5 x 5 midpoints.
    assert len(east) == 25


def test_ply_text_header_counts_the_points():
    text = ply_text(np.array([[0.0, 1.0, 2.0], [1.0, 2.0, 3.0]]), "a\nb")
    lines = text.splitlines()
    assert lines[:4] == ["ply", "format ascii 1.0", "comment a", "comment b"]
    assert "element vertex 2" in lines
    assert lines[-1] == "1.000 2.000 3.000"


def test_bad_spacing_is_refused(levels):
    with pytest.raises(ValueError, match="spacing"):
        wall_cloud(levels, spacing=0.0)
