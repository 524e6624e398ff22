"""RRT* in the plane of an elevation map under a slope limit (seeded, deterministic).

A segment is valid when every cell it crosses (sampled every quarter cell) is not steep and each
step between consecutive distinct cells obeys the move rule of :mod:`terrain`; its cost is the sum
of the 3-D lengths of those steps times the cost factor of the cell entered. The tree grows by
steering ``step_size`` towards a sample (the goal with probability ``goal_bias``), picks the
cheapest parent among the 8 closest nodes within a radius shrinking from ``neighbor_radius``
as the tree grows (the original's rule), and rewires the neighbours through the new node (costs
propagated to their subtrees). The best node within ``goal_threshold`` of the goal with a valid
segment to it ends the path. Same inputs and seed, same path. Pure; any thread.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from easynav.maps.gridmap import GridMap
from easynav.planners.gridmap.terrain import move_allowed

#: Parent candidates and rewiring targets per new node (the original keeps 8).
MAX_NEIGHBOURS = 8


@dataclass(frozen=True)
class RRTStarSettings:
    """The RRT* parameters (the original's names and defaults)."""

    max_iters: int = 3000
    step_size: float = 1.0
    neighbor_radius: float = 2.0
    goal_bias: float = 0.15
    goal_threshold: float = 0.5
    max_lateral_deviation: float = 0.5
    seed: int = 0


class TerrainSegments:
    """Validity and cost of straight segments on one map (holds the map's arrays; read-only)."""

    def __init__(self, grid: GridMap, factors: np.ndarray, max_slope_rad: float) -> None:
        self.grid = grid
        self.factors = factors
        self.max_slope_rad = max_slope_rad

    def cell_of(self, x: float, y: float) -> tuple[int, int] | None:
        """The cell holding ``(x, y)``, or None off the map."""
        ix, iy = self.grid.world_to_cell(x, y)
        ix, iy = int(ix), int(iy)
        return (ix, iy) if self.grid.in_bounds(ix, iy) else None

    def cost(self, a: np.ndarray, b: np.ndarray) -> float:
        """Cost of the segment ``a`` -> ``b`` (``inf`` when it is not allowed)."""
        grid = self.grid
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        samples = max(1, math.ceil(length / (0.25 * grid.resolution)))
        t = np.linspace(0.0, 1.0, samples + 1)
        ix, iy = grid.world_to_cell(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
        if not grid.in_bounds(ix, iy).all():
            return math.inf
        keep = np.ones(len(ix), bool)
        keep[1:] = (np.diff(ix) != 0) | (np.diff(iy) != 0)
        ix, iy = ix[keep], iy[keep]
        factors = self.factors[iy, ix]
        if np.isinf(factors[1:]).any():
            return math.inf
        z = grid.elevation[iy, ix]
        if len(ix) == 1:
            return length * float(factors[0])
        horizontal = grid.resolution * np.hypot(np.diff(ix), np.diff(iy))
        dz = np.abs(np.diff(z))
        slopes = np.arctan2(dz, horizontal)
        if (slopes > self.max_slope_rad + 1e-9).any():
            return math.inf
        # The segment's length shared among the steps, each lifted by its climb.
        piece = length * horizontal / horizontal.sum()
        return float(np.sum(np.hypot(piece, dz) * factors[1:]))

    def move_ok(self, a: tuple[int, int], b: tuple[int, int]) -> bool:
        """The move rule between two cells' centres."""
        z = self.grid.elevation
        horizontal = self.grid.resolution * math.hypot(b[0] - a[0], b[1] - a[1])
        return move_allowed(float(z[a[1], a[0]]), float(z[b[1], b[0]]), horizontal,
                            self.max_slope_rad)


def rrt_star(
    segments: TerrainSegments,
    start: tuple[float, float],
    goal: tuple[float, float],
    settings: RRTStarSettings,
) -> tuple[np.ndarray, float] | None:
    """``((K, 2) points start..goal, cost)`` or None when no path was found in ``max_iters``."""
    grid = segments.grid
    rng = np.random.default_rng(settings.seed)
    h, w = grid.shape
    low = np.array([grid.origin_x, grid.origin_y])
    high = low + np.array([w, h]) * grid.resolution
    goal_xy = np.asarray(goal, float)
    capacity = settings.max_iters + 1
    points = np.empty((capacity, 2))
    costs = np.empty(capacity)
    parents = np.full(capacity, -1)
    children: list[list[int]] = [[]]
    points[0] = start
    costs[0] = 0.0
    count = 1
    best_node, best_cost = -1, math.inf
    for _ in range(settings.max_iters):
        if rng.random() < settings.goal_bias:
            sample = goal_xy
        else:
            sample = low + rng.random(2) * (high - low)
        dist = np.hypot(*(points[:count] - sample).T)
        nearest = int(np.argmin(dist))
        gap = dist[nearest]
        if gap < 1e-9:
            continue
        step = min(settings.step_size, gap)
        new = points[nearest] + (sample - points[nearest]) * (step / gap)
        near_dist = np.hypot(*(points[:count] - new).T)
        if near_dist.min() < 0.5 * grid.resolution:
            continue  # a node is already here
        # The original's shrinking radius, and at most MAX_NEIGHBOURS of the closest nodes.
        radius = settings.neighbor_radius * min(1.0, math.sqrt(math.log(count + 1) / count))
        near = np.flatnonzero(near_dist <= max(radius, step))
        if len(near) > MAX_NEIGHBOURS:
            near = near[np.argsort(near_dist[near], kind="stable")[:MAX_NEIGHBOURS]]
        if nearest not in near:
            near = np.append(near, nearest)
        edge = {int(j): segments.cost(points[j], new) for j in near}
        totals = {j: costs[j] + c for j, c in edge.items() if math.isfinite(c)}
        if not totals:
            continue
        parent = min(totals, key=lambda j: (totals[j], j))
        node = count
        count += 1
        points[node], costs[node], parents[node] = new, totals[parent], parent
        children.append([])
        children[parent].append(node)
        # Rewire: the segment's cost is symmetric, so edge[j] serves both directions.
        for j, c in edge.items():
            if j == parent or not math.isfinite(c) or costs[node] + c >= costs[j] - 1e-9:
                continue
            if _is_ancestor(parents, j, node):
                continue
            children[parents[j]].remove(j)
            parents[j] = node
            children[node].append(j)
            _propagate(j, costs[node] + c, costs, children)
        if np.hypot(*(new - goal_xy)) <= settings.goal_threshold:
            to_goal = segments.cost(new, goal_xy)
            if math.isfinite(to_goal) and costs[node] + to_goal < best_cost:
                best_node, best_cost = node, costs[node] + to_goal
        # A rewire may have lowered the best goal node's cost.
        if best_node >= 0:
            best_cost = min(best_cost, costs[best_node] + segments.cost(points[best_node], goal_xy))
    if best_node < 0:
        return None
    chain = [best_node]
    while parents[chain[-1]] >= 0:
        chain.append(int(parents[chain[-1]]))
    path = points[chain[::-1]]
    if np.hypot(*(path[-1] - goal_xy)) > 1e-9:
        path = np.vstack([path, goal_xy])
    return path, best_cost


def _is_ancestor(parents: np.ndarray, candidate: int, node: int) -> bool:
    while node >= 0:
        if node == candidate:
            return True
        node = int(parents[node])
    return False


def _propagate(node: int, cost: float, costs: np.ndarray, children: list[list[int]]) -> None:
    """Set ``node``'s cost and shift its subtree by the same change."""
    delta = cost - costs[node]
    stack = [node]
    while stack:
        n = stack.pop()
        costs[n] += delta
        stack.extend(children[n])


def path_cost(segments: TerrainSegments, path: np.ndarray) -> float:
    """Cost of a polyline (``inf`` when a segment is not allowed)."""
    return float(sum(segments.cost(path[i], path[i + 1]) for i in range(len(path) - 1)))


def shortcut(segments: TerrainSegments, path: np.ndarray, max_lateral_deviation: float
             ) -> np.ndarray:
    """Drop intermediate points where the straight segment is allowed, no dearer than the
    points it replaces, and passes within ``max_lateral_deviation`` of each of them."""
    out = [path[0]]
    i = 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1:
            a, b = path[i], path[j]
            direct = segments.cost(a, b)
            if math.isfinite(direct) and direct <= path_cost(segments, path[i:j + 1]) + 1e-9:
                if _max_deviation(a, b, path[i + 1:j]) <= max_lateral_deviation:
                    break
            j -= 1
        out.append(path[j])
        i = j
    return np.array(out)


def _max_deviation(a: np.ndarray, b: np.ndarray, points: np.ndarray) -> float:
    if len(points) == 0:
        return 0.0
    ab = b - a
    norm = math.hypot(*ab)
    if norm < 1e-12:
        return float(np.max(np.hypot(*(points - a).T)))
    t = np.clip(((points - a) @ ab) / (norm * norm), 0.0, 1.0)
    closest = a + t[:, None] * ab
    return float(np.max(np.hypot(*(points - closest).T)))


def resample(path: np.ndarray, spacing: float) -> np.ndarray:
    """Points every ``spacing`` m along the polyline (its vertices' ends kept)."""
    out = [path[0]]
    for a, b in zip(path[:-1], path[1:], strict=True):
        length = math.hypot(*(b - a))
        pieces = max(1, math.ceil(length / spacing - 1e-9))
        for k in range(1, pieces + 1):
            out.append(a + (b - a) * (k / pieces))
    return np.array(out)
