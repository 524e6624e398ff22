"""NavMap type: geometry, adjacency, point location (against brute force), layers."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.maps.navmap import LETHAL_OBSTACLE, NavMap, TriangleGrid, locate_reference

spatial = pytest.importorskip("scipy.spatial")


def grid_mesh(nx: int, ny: int, res: float = 1.0, z: float = 0.0) -> NavMap:
    """Two triangles per cell, as the original's from_occupancy_grid."""
    xs, ys = np.meshgrid(np.arange(nx + 1) * res, np.arange(ny + 1) * res)
    vertices = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, z)])
    faces = []
    for j in range(ny):
        for i in range(nx):
            v = lambda a, b: b * (nx + 1) + a  # noqa: E731
            faces.append((v(i, j), v(i + 1, j), v(i + 1, j + 1)))
            faces.append((v(i, j), v(i + 1, j + 1), v(i, j + 1)))
    return NavMap(vertices, faces)


def random_mesh(rng, n_points: int, extent: float = 10.0, floors: int = 1) -> NavMap:
    """A random 2.5-D Delaunay surface; ``floors`` stacked copies 3 m apart."""
    verts, faces = [], []
    for f in range(floors):
        xy = rng.uniform(0, extent, size=(n_points, 2))
        z = 3.0 * f + 0.3 * np.sin(xy[:, 0]) * np.cos(xy[:, 1])
        tri = spatial.Delaunay(xy).simplices
        faces.append(tri + sum(len(v) for v in verts))
        verts.append(np.column_stack([xy, z]))
    return NavMap(np.vstack(verts), np.vstack(faces))


def brute_force(navmap: NavMap, points: np.ndarray, height_eps=None, downward=False):
    """Vectorised all-pairs location (its own barycentric formula)."""
    tri = navmap.vertices[navmap.faces]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    p = points[:, None, :2]
    a2 = a[None, :, :2]
    v0, v1, v2 = b[None, :, :2] - a2, c[None, :, :2] - a2, p - a2
    den = v0[..., 0] * v1[..., 1] - v1[..., 0] * v0[..., 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        lb = (v2[..., 0] * v1[..., 1] - v1[..., 0] * v2[..., 1]) / den
        lc = (v0[..., 0] * v2[..., 1] - v2[..., 0] * v0[..., 1]) / den
    la = 1 - lb - lc
    inside = (np.abs(den) > 1e-12) & (la >= -1e-4) & (lb >= -1e-4) & (lc >= -1e-4)
    zs = la * a[None, :, 2] + lb * b[None, :, 2] + lc * c[None, :, 2]
    dz = points[:, None, 2] - zs
    if downward:
        inside &= dz >= -(height_eps or 0.0)
        score = np.where(inside, dz, np.inf)
    else:
        if height_eps is not None:
            inside &= np.abs(dz) <= height_eps
        score = np.where(inside, np.abs(dz), np.inf)
    best = np.argmin(score, axis=1)
    found = np.isfinite(score[np.arange(len(points)), best])
    return np.where(found, best, -1), score


@pytest.mark.parametrize("floors", [1, 2])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_locate_matches_brute_force(seed, floors):
    rng = np.random.default_rng(seed)
    navmap = random_mesh(rng, 300, floors=floors)
    points = np.column_stack([
        rng.uniform(-1, 11, size=(2000, 2)), rng.uniform(-1, 3.0 * floors + 1, size=2000)
    ])
    for height_eps, downward in [(None, False), (0.5, False), (0.5, True), (None, True)]:
        cids, heights = navmap.locate(points, height_eps, downward)
        expected, score = brute_force(navmap, points, height_eps, downward)
        assert np.array_equal(cids >= 0, expected >= 0)
        rows = np.flatnonzero(cids >= 0)
        # Same triangle, or a tie on a shared edge (equal score).
        same = cids[rows] == expected[rows]
        tie = np.isclose(score[rows, cids[rows]], score[rows, expected[rows]], atol=1e-9)
        assert (same | tie).all()
        assert np.isnan(heights[cids < 0]).all()


def test_locate_reference_agrees_with_grid():
    rng = np.random.default_rng(5)
    navmap = random_mesh(rng, 200, floors=2)
    points = np.column_stack([rng.uniform(0, 10, size=(300, 2)), rng.uniform(-1, 4, 300)])
    got = navmap.locate(points)
    ref = locate_reference(navmap.grid, points)
    assert np.array_equal(got[0], ref[0])
    np.testing.assert_allclose(got[1], ref[1])


def test_two_floors_nearest_and_downward():
    lower = grid_mesh(4, 4, z=0.0)
    verts = np.vstack([lower.vertices, lower.vertices + (0, 0, 3.0)])
    faces = np.vstack([lower.faces, lower.faces + lower.num_vertices])
    navmap = NavMap(verts, faces)
    m = lower.num_navcels
    assert navmap.locate_navcel((1.3, 2.6, 0.2)) < m
    assert navmap.locate_navcel((1.3, 2.6, 2.7)) >= m
    assert navmap.locate_navcel((1.3, 2.6, 2.0)) >= m  # nearer to 3.0 than to 0.0
    assert navmap.locate_navcel((1.3, 2.6, 2.0), downward=True) < m
    assert navmap.locate_navcel((1.3, 2.6, 2.8), downward=True, height_eps=0.5) >= m
    assert navmap.locate_navcel((1.3, 2.6, 1.5), height_eps=0.5) is None
    assert navmap.locate_navcel((9.0, 9.0, 0.0)) is None
    cids, heights = navmap.locate(np.array([[0.5, 0.25, 0.4], [0.5, 0.25, 2.9]]))
    np.testing.assert_allclose(heights, [0.0, 3.0])


def test_locate_on_slope_interpolates_height():
    verts = np.array([[0, 0, 0], [2, 0, 1], [2, 2, 1], [0, 2, 0]], dtype=float)
    navmap = NavMap(verts, [[0, 1, 2], [0, 2, 3]])
    cids, heights = navmap.locate(np.array([[1.5, 0.5, 5.0], [0.5, 1.5, -5.0]]))
    assert list(cids) == [0, 1]
    np.testing.assert_allclose(heights, [0.75, 0.25])


def test_vertical_triangles_are_not_located():
    verts = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1]], dtype=float)
    navmap = NavMap(verts, [[0, 1, 2]])
    assert navmap.locate_navcel((0.5, 0.0, 0.5)) is None


def test_grid_cell_size_and_empty():
    navmap = grid_mesh(3, 3)
    grid = TriangleGrid(navmap.vertices, navmap.faces, cell_size=0.5)
    assert grid.nx == 7 and grid.ny == 7
    cids, _ = grid.locate(np.array([[1.2, 1.7, 0.0]]))
    assert cids[0] == navmap.locate_navcel((1.2, 1.7, 0.0))
    empty = NavMap(np.zeros((0, 3)), np.zeros((0, 3), dtype=int))
    assert empty.locate_navcel((0, 0, 0)) is None


def test_adjacency_centroids_normals():
    navmap = grid_mesh(2, 1)
    # cell (0,0): t0 = (0,1,4), t1 = (0,4,3); cell (1,0): t2 = (1,2,5), t3 = (1,5,4)
    assert navmap.navcel_neighbors(0) == [3, 1]
    assert sorted(navmap.navcel_neighbors(3)) == [0, 2]
    assert navmap.neighbors[0, 1] == 3  # edge (1, 4)
    assert navmap.neighbors[0, 2] == 1  # edge (4, 0)
    assert navmap.neighbors[0, 0] == -1
    assert navmap.boundary_mask().all()
    np.testing.assert_allclose(navmap.centroids[0], [2 / 3, 1 / 3, 0])
    np.testing.assert_allclose(navmap.normals, np.tile([0, 0, 1.0], (4, 1)))
    np.testing.assert_allclose(navmap.areas, 0.5)
    inner = grid_mesh(3, 3)
    assert (~inner.boundary_mask()).sum() > 0
    with pytest.raises(ValueError):
        navmap.vertices[0, 0] = 1.0


def test_non_manifold_edge_pairs_first_two():
    verts = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0.5, 1]], float)
    navmap = NavMap(verts, [[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    assert navmap.neighbors[0, 0] == 1 and navmap.neighbors[1, 0] == 0
    assert navmap.neighbors[2, 0] == -1


def test_invalid_geometry():
    with pytest.raises(ValueError, match="outside"):
        NavMap(np.zeros((3, 3)), [[0, 1, 3]])
    with pytest.raises(ValueError, match="finite"):
        NavMap([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


def test_layers():
    navmap = grid_mesh(2, 2)
    occ = navmap.add_layer("obstacles")
    assert occ.dtype == np.uint8 and len(occ) == navmap.num_navcels
    navmap.layer_set("obstacles", 3, LETHAL_OBSTACLE)
    assert navmap.layer_get("obstacles", 3) == 254
    assert navmap.layer_get("obstacles", 99, default=-1) == -1
    assert navmap.layer_get("nope", 0) is None
    navmap.set_layer("elevation", navmap.centroids[:, 2].astype(np.float32))
    assert navmap.layer_type_name("elevation") == "float"
    navmap.add_layer("d", np.float64, 1.5)
    assert navmap.layer_type_name("d") == "double"
    assert navmap.list_layers() == ["obstacles", "elevation", "d"]
    with pytest.raises(ValueError, match="uint8"):
        navmap.add_layer("obstacles", np.float32)
    with pytest.raises(ValueError, match="int16"):
        navmap.add_layer("bad", np.int16)
    with pytest.raises(ValueError, match="NavCels"):
        navmap.set_layer("short", np.zeros(3, np.uint8))
    with pytest.raises(KeyError, match="obstacles"):
        navmap.layer("missing")
    navmap.layer_clear("obstacles", 7)
    assert (navmap.layer("obstacles") == 7).all()
    assert navmap.sample_layer_at("d", (0.5, 0.2, 0.0)) == 1.5
    assert np.isnan(navmap.sample_layer_at("d", (50, 50, 0)))
    assert navmap.remove_layer("d") and not navmap.has_layer("d")


def test_copy_shares_geometry_not_layers():
    navmap = grid_mesh(3, 3)
    navmap.add_layer("obstacles")
    navmap.locate_navcel((1, 1, 0))
    dup = navmap.copy()
    dup.layer_set("obstacles", 0, 254)
    assert navmap.layer_get("obstacles", 0) == 0
    assert dup.same_geometry(navmap) and dup.grid is navmap.grid
    assert not dup.same_geometry(grid_mesh(3, 2))


def test_set_area():
    navmap = grid_mesh(10, 10, res=0.5)
    assert navmap.set_area((2.5, 2.5, 0.0), 254, "obstacles", "circular", 1.0)
    layer = navmap.layer("obstacles")
    d = np.linalg.norm(navmap.centroids[:, :2] - (2.5, 2.5), axis=1)
    assert np.array_equal(layer == 254, d <= 1.0)
    assert navmap.set_area((1.0, 1.0, 0.0), 9, "obstacles", "rectangular", 1.0)
    sq = (np.abs(navmap.centroids[:, :2] - (1.0, 1.0)) <= 0.5).all(axis=1)
    assert (layer[sq] == 9).all()
    assert not navmap.set_area((50, 50, 0), 1, "obstacles")


def test_adjacency_pairs_cached_and_shared_by_copies():
    navmap = grid_mesh(3, 2)
    u, v = navmap.adjacency_pairs()
    expected = {(c, int(n)) for c in range(navmap.num_navcels) for n in navmap.neighbors[c]
                if n >= 0}
    assert set(zip(u.tolist(), v.tolist(), strict=True)) == expected
    assert len(u) == len(expected) and (np.diff(u) >= 0).all()
    dup = navmap.copy()
    assert dup.adjacency_pairs()[0] is u
