"""NavMap: a navigable triangle surface with named per-triangle layers (EasyNavigation/NavMap)."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from easynav.maps.navmap.triangle_grid import PLANAR_EPS, TriangleGrid

#: Cost values of the original (navmap_ros/conversions.hpp, Nav2's).
FREE_SPACE = 0
INSCRIBED_INFLATED_OBSTACLE = 253
LETHAL_OBSTACLE = 254
NO_INFORMATION = 255

#: Layer storage types of the original (``LayerType``: U8 = 0, F32 = 1, F64 = 2).
LAYER_DTYPES = (np.dtype(np.uint8), np.dtype(np.float32), np.dtype(np.float64))
_TYPE_NAMES = {np.dtype(np.uint8): "uint8", np.dtype(np.float32): "float",
               np.dtype(np.float64): "double"}


@dataclass
class Surface:
    """A set of NavCels in a frame (the original's ``Surface``: ``frame_id``, ``navcels``)."""

    frame_id: str = ""
    navcels: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.uint32))


class NavMap:
    """A surface of triangles ("NavCels") with named per-NavCel layers, as the original's
    ``navmap::NavMap``.

    Geometry (immutable once built; read-only arrays): ``vertices`` (N, 3) float64,
    ``faces`` (M, 3) int64 (vertex indices of each NavCel), and derived ``neighbors`` (M, 3)
    int64 — ``neighbors[c, e]`` is the NavCel across edge ``(faces[c, e], faces[c, (e+1)%3])``
    or -1 at a border, as the original's ``build_adjacency`` — ``centroids`` (M, 3), unit
    ``normals`` (M, 3) (right-handed from the vertex order) and ``areas`` (M,). ``surfaces``
    partition the NavCels (the file format carries them; a map without any gets one surface of
    every NavCel), ``colors`` is an optional (N, 4) uint8 RGBA per vertex.

    Layers hold one value per NavCel (the original has no per-vertex layers), of dtype uint8,
    float32 or float64 (the original's U8/F32/F64). Cost layers use uint8 with 0 free, 253
    inscribed, 254 lethal, 255 unknown (:data:`LETHAL_OBSTACLE` ...).

    Point location (:meth:`locate`): the NavCel under a 3-D point along a vertical ray,
    through a :class:`TriangleGrid` built on first use.

    NavState: stored under ``map.navmap`` by the NavMapMapsManager. :meth:`copy` shares the
    geometry and the spatial index and copies the layers, so a filter changes a copy's layers
    without touching the map another thread reads.

    Thread contract: geometry and index are immutable and may be read from any thread; layers
    are plain numpy arrays, mutated only by the owner of this instance (copy before changing
    a map that is published in NavState). Exceptions: ``ValueError`` for malformed geometry,
    layer values of the wrong size or dtype; ``KeyError`` for a missing layer.
    """

    def __init__(
        self,
        vertices: np.ndarray,
        faces: np.ndarray,
        *,
        surfaces: list[Surface] | None = None,
        colors: np.ndarray | None = None,
        frame_id: str = "map",
    ) -> None:
        vertices = np.array(vertices, dtype=np.float64).reshape(-1, 3)
        faces = np.array(faces, dtype=np.int64).reshape(-1, 3)
        if not np.isfinite(vertices).all():
            raise ValueError("NavMap: vertices must be finite")
        if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError(
                f"NavMap: a face indexes a vertex outside 0..{len(vertices) - 1}"
            )
        if colors is not None:
            colors = np.array(colors, dtype=np.uint8).reshape(-1, 4)
            if len(colors) != len(vertices):
                raise ValueError(
                    f"NavMap: {len(colors)} colors for {len(vertices)} vertices"
                )
            colors.flags.writeable = False
        self._vertices = vertices
        self._faces = faces
        self._colors = colors
        self.frame_id = frame_id
        tri = vertices[faces]
        self._centroids = tri.mean(axis=1)
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        norm = np.linalg.norm(cross, axis=1)
        self._areas = 0.5 * norm
        normals = np.zeros_like(cross)
        normals[:, 2] = 1.0
        good = norm > 0
        normals[good] = cross[good] / norm[good, None]
        self._normals = normals
        self._neighbors = _build_adjacency(faces)
        if surfaces is None or len(surfaces) == 0:
            surfaces = [Surface(frame_id, np.arange(len(faces), dtype=np.uint32))]
        self._surfaces = [
            Surface(s.frame_id, np.asarray(s.navcels, dtype=np.uint32)) for s in surfaces
        ]
        for s in self._surfaces:
            if len(s.navcels) and int(s.navcels.max()) >= len(faces):
                raise ValueError(f"NavMap: surface {s.frame_id!r} lists a NavCel past {len(faces)}")
        for array in (vertices, faces, self._centroids, self._areas, normals, self._neighbors):
            array.flags.writeable = False
        self._grid: TriangleGrid | None = None
        self._layers: dict[str, np.ndarray] = {}
        #: Structures derived from the geometry, computed on demand, shared by the copies.
        self.geometry_cache: dict = {}

    # -- geometry ---------------------------------------------------------------------------
    @property
    def vertices(self) -> np.ndarray:
        """(N, 3) float64 vertex positions (read-only)."""
        return self._vertices

    @property
    def faces(self) -> np.ndarray:
        """(M, 3) int64 vertex indices of each NavCel (read-only)."""
        return self._faces

    @property
    def neighbors(self) -> np.ndarray:
        """(M, 3) int64 NavCel across each edge, -1 at a border (read-only)."""
        return self._neighbors

    @property
    def centroids(self) -> np.ndarray:
        """(M, 3) float64 NavCel centroids (read-only)."""
        return self._centroids

    @property
    def normals(self) -> np.ndarray:
        """(M, 3) float64 unit normals (``+z`` for a degenerate NavCel; read-only)."""
        return self._normals

    @property
    def areas(self) -> np.ndarray:
        """(M,) float64 NavCel areas in m² (read-only)."""
        return self._areas

    @property
    def surfaces(self) -> list[Surface]:
        """Surfaces (frame id and NavCel ids), as stored in the file format."""
        return self._surfaces

    @property
    def colors(self) -> np.ndarray | None:
        """(N, 4) uint8 RGBA per vertex, or None."""
        return self._colors

    @property
    def num_navcels(self) -> int:
        """Number of NavCels (triangles)."""
        return len(self._faces)

    @property
    def num_vertices(self) -> int:
        """Number of vertices."""
        return len(self._vertices)

    def navcel_neighbors(self, cid: int) -> list[int]:
        """The up-to-3 NavCels sharing an edge with ``cid`` (borders skipped)."""
        return [int(n) for n in self._neighbors[cid] if n >= 0]

    def adjacency_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """Directed neighbour pairs ``(u, v)`` (each shared edge both ways, duplicates removed),
        int64 arrays sorted by ``u``; cached in :attr:`geometry_cache`."""
        pairs = self.geometry_cache.get("adjacency_pairs")
        if pairs is None:
            m = self.num_navcels
            u = np.repeat(np.arange(m, dtype=np.int64), 3)
            v = self._neighbors.reshape(-1)
            keys = np.unique(u[v >= 0] * max(m, 1) + v[v >= 0])
            pairs = (keys // max(m, 1), keys % max(m, 1))
            for a in pairs:
                a.flags.writeable = False
            self.geometry_cache["adjacency_pairs"] = pairs
        return pairs

    def boundary_mask(self) -> np.ndarray:
        """(M,) bool: NavCels with fewer than 3 neighbours (on the border of the surface)."""
        return (self._neighbors < 0).any(axis=1)

    def same_geometry(self, other: NavMap) -> bool:
        """True if ``other`` has the same vertices and faces (the original's
        ``has_same_geometry``)."""
        return self._faces is other._faces or (
            np.array_equal(self._faces, other._faces)
            and np.array_equal(self._vertices, other._vertices)
        )

    # -- point location ---------------------------------------------------------------------
    @property
    def grid(self) -> TriangleGrid:
        """The spatial index (built on first use, then shared by copies)."""
        if self._grid is None:
            self._grid = TriangleGrid(self._vertices, self._faces)
        return self._grid

    def locate(
        self,
        points: np.ndarray,
        height_eps: float | None = None,
        downward: bool = False,
        planar_eps: float = PLANAR_EPS,
    ) -> tuple[np.ndarray, np.ndarray]:
        """NavCel under each 3-D point along a vertical ray (vectorised).

        Candidates are the NavCels whose xy projection contains the point's (x, y) (barycentric
        tolerance ``planar_eps``, the original's 1e-4). By default the one whose surface height
        there is nearest to the point's z wins — the original's ``locate_navcel``, which casts a
        ray down and one up and keeps the hit with the smaller ``|dz|``; ``height_eps`` then
        rejects a hit farther than that. With ``downward=True`` only a downward ray starting
        ``height_eps`` (default 0) above the point counts: the highest surface at or below
        ``z + height_eps``. Ties go to the lower NavCel id.

        Returns ``(cids, heights)``: (K,) int64 NavCel ids (-1 where none) and (K,) float64
        surface heights at the points (NaN where none).
        """
        return self.grid.locate(points, height_eps, downward, planar_eps)

    def locate_navcel(
        self, point, height_eps: float | None = None, downward: bool = False
    ) -> int | None:
        """NavCel under one point (see :meth:`locate`), or None."""
        cids, _ = self.locate(np.asarray(point, dtype=np.float64)[None, :3], height_eps, downward)
        return None if cids[0] < 0 else int(cids[0])

    # -- layers -----------------------------------------------------------------------------
    def add_layer(self, name: str, dtype=np.uint8, default: float = 0) -> np.ndarray:
        """Create (or get) a per-NavCel layer filled with ``default``; returns its array.

        An existing layer of another dtype raises ``ValueError``.
        """
        dtype = _layer_dtype(dtype, name)
        layer = self._layers.get(name)
        if layer is not None:
            if layer.dtype != dtype:
                raise ValueError(
                    f"NavMap layer {name!r} is {_TYPE_NAMES[layer.dtype]}, not {_TYPE_NAMES[dtype]}"
                )
            return layer
        layer = np.full(self.num_navcels, default, dtype=dtype)
        self._layers[name] = layer
        return layer

    def set_layer(self, name: str, values: np.ndarray, dtype=None) -> np.ndarray:
        """Replace (or create) layer ``name`` with ``values`` (one per NavCel); returns it.

        ``dtype`` defaults to the values' dtype; it must be uint8, float32 or float64.
        """
        values = np.asarray(values)
        dtype = _layer_dtype(values.dtype if dtype is None else dtype, name)
        if values.shape != (self.num_navcels,):
            raise ValueError(
                f"NavMap layer {name!r}: {values.shape} values for {self.num_navcels} NavCels"
            )
        layer = np.array(values, dtype=dtype)
        self._layers[name] = layer
        return layer

    def layer(self, name: str) -> np.ndarray:
        """The array of layer ``name`` (mutable; KeyError naming the layers if absent)."""
        try:
            return self._layers[name]
        except KeyError:
            raise KeyError(
                f"NavMap has no layer {name!r} (layers: {sorted(self._layers)})"
            ) from None

    def has_layer(self, name: str) -> bool:
        """True if layer ``name`` exists."""
        return name in self._layers

    def remove_layer(self, name: str) -> bool:
        """Remove layer ``name``; True if it existed."""
        return self._layers.pop(name, None) is not None

    def list_layers(self) -> list[str]:
        """Layer names in creation order."""
        return list(self._layers)

    def layer_type_name(self, name: str) -> str:
        """``"uint8"``, ``"float"`` or ``"double"`` (the original's names)."""
        return _TYPE_NAMES[self.layer(name).dtype]

    def layer_get(self, name: str, cid: int, default=None):
        """Value of layer ``name`` at NavCel ``cid``, or ``default`` (missing layer or id)."""
        layer = self._layers.get(name)
        if layer is None or not 0 <= cid < len(layer):
            return default
        return layer[cid].item()

    def layer_set(self, name: str, cid, value, dtype=np.uint8) -> None:
        """Set layer ``name`` at NavCel(s) ``cid`` (created with ``dtype`` if missing)."""
        self.add_layer(name, dtype)[cid] = value

    def layer_clear(self, name: str, value=0, dtype=np.uint8) -> np.ndarray:
        """Fill layer ``name`` with ``value`` (created with ``dtype`` if missing)."""
        layer = self.add_layer(name, dtype)
        layer.fill(value)
        return layer

    def sample_layer_at(self, name: str, point, default: float = float("nan")) -> float:
        """Value of layer ``name`` at the NavCel under ``point`` (nearest in z), or ``default``."""
        cid = self.locate_navcel(point)
        if cid is None or name not in self._layers:
            return default
        return float(self._layers[name][cid])

    def set_area(self, point, value, layer: str, shape: str = "circular", size: float = 1.0,
                 dtype=np.uint8) -> bool:
        """Set ``layer`` to ``value`` on the NavCels around ``point`` (the original's
        ``set_area``): breadth-first from the NavCel under the point through neighbours whose
        xy box meets the area's square; a NavCel is set when its centroid is inside the circle
        of radius ``size`` (``"circular"``) or the square of side ``size`` (``"rectangular"``).
        False when the point locates on no NavCel or ``size <= 0``."""
        if size <= 0 or self.num_navcels == 0:
            return False
        cids, heights = self.locate(np.asarray(point, dtype=np.float64)[None, :3])
        if cids[0] < 0:
            return False
        data = self.add_layer(layer, dtype)
        cx, cy = float(point[0]), float(point[1])
        circular = shape.lower().startswith("c")
        half = size if circular else 0.5 * size
        tri = self._vertices[self._faces]
        lo, hi = tri[:, :, :2].min(axis=1), tri[:, :, :2].max(axis=1)
        touches = (hi[:, 0] >= cx - half) & (lo[:, 0] <= cx + half) & (
            hi[:, 1] >= cy - half) & (lo[:, 1] <= cy + half)
        d = self._centroids[:, :2] - (cx, cy)
        inside = (d ** 2).sum(axis=1) <= size * size if circular else (np.abs(d) <= half).all(1)
        seen = np.zeros(self.num_navcels, dtype=bool)
        start = int(cids[0])
        seen[start] = True
        queue = deque([start])
        while queue:
            c = queue.popleft()
            if not touches[c]:
                continue
            if inside[c]:
                data[c] = value
            for n in self._neighbors[c]:
                if n >= 0 and not seen[n] and touches[n]:
                    seen[n] = True
                    queue.append(int(n))
        return True

    # -- copies -----------------------------------------------------------------------------
    def copy(self) -> NavMap:
        """A map sharing this geometry (and spatial index) with copies of the layers."""
        out = NavMap.__new__(NavMap)
        out.__dict__.update(self.__dict__)
        out._layers = {name: layer.copy() for name, layer in self._layers.items()}
        return out

    def __repr__(self) -> str:
        return (
            f"NavMap({self.num_vertices} vertices, {self.num_navcels} NavCels, "
            f"{len(self._surfaces)} surfaces, layers {self.list_layers()})"
        )


def _layer_dtype(dtype, name: str) -> np.dtype:
    dtype = np.dtype(dtype)
    if dtype not in LAYER_DTYPES:
        raise ValueError(
            f"NavMap layer {name!r}: dtype {dtype} is not one of uint8, float32, float64"
        )
    return dtype


def _build_adjacency(faces: np.ndarray) -> np.ndarray:
    """(M, 3) neighbour across each edge (-1 at a border), vectorised.

    Edge ``e`` of NavCel ``c`` is ``(faces[c, e], faces[c, (e+1) % 3])``. Two NavCels sharing
    an undirected edge are neighbours; on a non-manifold edge (more than two NavCels) the first
    two in id order are paired, the others stay without a neighbour there.
    """
    m = len(faces)
    neighbors = np.full((m, 3), -1, dtype=np.int64)
    if m == 0:
        return neighbors
    a = faces.reshape(-1)
    b = faces[:, [1, 2, 0]].reshape(-1)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * (int(faces.max()) + 1) + hi
    order = np.argsort(key, kind="stable")
    k = key[order]
    same = np.flatnonzero(k[1:] == k[:-1])
    # pair i with i+1 only where i starts a run (not the second of a previous pair)
    starts = same[(same == 0) | (k[same] != k[np.maximum(same - 1, 0)])]
    first, second = order[starts], order[starts + 1]
    flat = neighbors.reshape(-1)
    flat[first] = second // 3
    flat[second] = first // 3
    return neighbors
