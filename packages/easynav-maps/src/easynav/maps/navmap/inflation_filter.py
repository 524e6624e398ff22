"""InflationFilter (easynav_navmap_maps_manager/NavMapMapsManager/InflationFilter)."""

from __future__ import annotations

import heapq
import math

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.navmap.navmap import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    NavMap,
)
from easynav.maps.navmap.navmap_filter import NavMapFilter


def inflation_cost(d: np.ndarray, radius: float, scaling: float, inscribed: float) -> np.ndarray:
    """The original's ``cost_from_dist``: 254 at ``d <= 0``, 253 within ``inscribed``, 0 beyond
    ``radius``, else ``lround(252 · exp(-scaling · (d - inscribed)))`` (uint8)."""
    d = np.asarray(d, dtype=np.float64)
    r_ins = min(max(inscribed, 0.0), radius)
    with np.errstate(over="ignore", invalid="ignore"):
        c = np.clip(np.exp(-scaling * (d - r_ins)) * (INSCRIBED_INFLATED_OBSTACLE - 1), 0,
                    INSCRIBED_INFLATED_OBSTACLE - 1)
    out = np.floor(c + 0.5)
    out = np.where(d <= r_ins, INSCRIBED_INFLATED_OBSTACLE, out)
    out = np.where(d > radius, FREE_SPACE, out)
    out = np.where(d <= 0, LETHAL_OBSTACLE, out)
    return out.astype(np.uint8)


def inflation_seeds(navmap: NavMap, src: np.ndarray) -> np.ndarray:
    """(M,) bool: the Dijkstra sources — lethal NavCels and border NavCels (< 3 neighbours)."""
    return (src == LETHAL_OBSTACLE) | navmap.boundary_mask()


def inflation_distances(navmap: NavMap, src: np.ndarray, radius: float) -> np.ndarray:
    """(M,) multi-source Dijkstra distance (xy centroid steps over NavCel adjacency) from the
    seeds, never entering an unknown (255) NavCel, bounded by ``radius`` (inf beyond).

    Through ``scipy.sparse.csgraph.dijkstra`` when scipy is installed, else
    :func:`inflation_distances_reference`."""
    try:
        from scipy.sparse import csr_matrix
        from scipy.sparse.csgraph import dijkstra
    except ImportError:
        return inflation_distances_reference(navmap, src, radius)
    m = navmap.num_navcels
    seeds = np.flatnonzero(inflation_seeds(navmap, src))
    if len(seeds) == 0:
        return np.full(m, np.inf)
    cache = navmap.geometry_cache
    if "inflation_edges" not in cache:
        u, v = navmap.adjacency_pairs()
        c = navmap.centroids[:, :2]
        w = np.linalg.norm(c[u] - c[v], axis=1)
        ok = w > 0  # the original skips zero steps
        u, v, w = u[ok], v[ok], w[ok]
        cache["inflation_edges"] = (u, v, w, csr_matrix((w, (u, v)), shape=(m, m)))
    u, v, w, graph = cache["inflation_edges"]
    blocked = src[v] == NO_INFORMATION
    if blocked.any():  # never enter an unknown NavCel
        keep = ~blocked
        graph = csr_matrix((w[keep], (u[keep], v[keep])), shape=(m, m))
    out = dijkstra(graph, directed=True, indices=seeds, min_only=True, limit=radius)
    return np.where(out <= radius, out, np.inf)


def inflation_distances_reference(navmap: NavMap, src: np.ndarray, radius: float) -> np.ndarray:
    """:func:`inflation_distances` as the original writes it: a heap, one NavCel at a time."""
    seeds = inflation_seeds(navmap, src)
    dist = np.full(navmap.num_navcels, np.inf)
    heap = [(0.0, int(c)) for c in np.flatnonzero(seeds)]
    dist[seeds] = 0.0
    c = navmap.centroids[:, :2]
    while heap:
        du, u = heapq.heappop(heap)
        if du != dist[u] or du > radius:
            continue
        for v in navmap.neighbors[u]:
            if v < 0 or src[v] == NO_INFORMATION:
                continue
            step = float(np.hypot(*(c[u] - c[v])))
            if step <= 0:
                continue
            alt = du + step
            if alt < dist[v] and alt <= radius:
                dist[v] = alt
                heapq.heappush(heap, (alt, int(v)))
    return dist


def inflate_layer(
    navmap: NavMap, src_layer: str, dst_layer: str, radius: float, scaling: float,
    inscribed: float, distances=inflation_distances,
) -> np.ndarray:
    """Write ``dst_layer`` (uint8) from ``src_layer``, the original's ``inflate_layer_u8``:
    seeds (lethal and border NavCels) 254, unknown NavCels 255, the others the
    :func:`inflation_cost` of their Dijkstra distance (0 when unreached). Returns the layer.

    Raises ``KeyError`` if ``src_layer`` is missing and ``ValueError`` if it is not uint8."""
    src = navmap.layer(src_layer)
    if src.dtype != np.uint8:
        raise ValueError(f"NavMap layer {src_layer!r} is {src.dtype}, the inflation needs uint8")
    dist = distances(navmap, src, radius)
    cost = inflation_cost(dist, radius, scaling, inscribed)
    seeds = inflation_seeds(navmap, src)
    cost[(src == NO_INFORMATION) & ~seeds] = NO_INFORMATION
    cost[seeds] = LETHAL_OBSTACLE
    return navmap.set_layer(dst_layer, cost, np.uint8)


class InflationFilter(NavMapFilter):
    """Inflates the layer ``obstacles`` into the layer ``inflated_obstacles`` (uint8).

    As the original: a multi-source Dijkstra over NavCel adjacency, steps = xy distances
    between centroids, from the lethal (254) NavCels **and from the border NavCels** (fewer than
    3 neighbours), never entering an unknown (255) NavCel and bounded by ``inflation_radius``.
    Costs: 254 on the seeds, 253 within ``inscribed_radius`` (clamped to the radius),
    ``round(252 · exp(-cost_scaling_factor · (d - inscribed_radius)))`` up to the radius, 0
    beyond or unreached; unknown NavCels stay 255. The layer is rewritten every cycle. Without
    an ``obstacles`` layer (no ObstaclesFilter before it) the map is left as is, with a
    throttled error (the original logs "inflate_layer_u8() failed").

    The inscribed radius is ``system_node.robot_geometry.inscribed_radius`` (which defaults to
    ``robot_geometry.radius``; both 0.3 by default, the original filter's own default). The
    filter's ``inscribed_radius`` is deprecated: set, it applies (with a warning) only where the
    params file sets neither ``robot_geometry.inscribed_radius`` nor ``robot_geometry.radius``;
    robot_geometry takes precedence otherwise.

    Thread contract: as :class:`NavMapFilter` (non-RT thread). Exceptions: configuration errors
    name the parameter.
    """

    PARAMETERS = (
        Param("inflation_radius", 0.30, "distance up to which costs decay", "m", gt=0.0),
        Param("cost_scaling_factor", 3.0, "exponential decay rate of the cost", "1/m", gt=0.0),
        Param("inscribed_radius", math.nan,
              "deprecated: system_node.robot_geometry.inscribed_radius is used (unset here)",
              "m", ge=0.0, allow_nan=True),
    )
    LAYER_NAME = "inflated_obstacles"
    SOURCE_LAYER = "obstacles"

    def __init__(self) -> None:
        super().__init__()
        self._throttle = WarningThrottle(period=5.0)

    def update(self, nav_state: NavState, navmap: NavMap) -> None:
        """Rewrite ``inflated_obstacles`` of ``navmap`` in place. Non-RT thread."""
        if not navmap.has_layer(self.SOURCE_LAYER):
            self._throttle.warn(
                self.logger, "no-source",
                f"{self.plugin_name}: the NavMap has no layer '{self.SOURCE_LAYER}' to inflate "
                "(list an ObstaclesFilter before the InflationFilter)",
            )
            return
        p = self.params
        inflate_layer(navmap, self.SOURCE_LAYER, self.LAYER_NAME, p.inflation_radius,
                      p.cost_scaling_factor, self.inscribed_radius())

    def on_initialize(self) -> None:
        self.inscribed_radius()  # warn now about a deprecated setting, not at the first cycle

    def inscribed_radius(self) -> float:
        """The inscribed radius in use (m): robot_geometry's, or the deprecated parameter."""
        return self.geometry_or_deprecated("inscribed_radius", "inscribed_radius",
                                           also_set_by=("radius",))
