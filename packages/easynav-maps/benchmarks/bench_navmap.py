"""NavMap point location: 1M queries on a 100k-triangle mesh, against brute force and trimesh.

    .venv/bin/python packages/easynav-maps/benchmarks/bench_navmap.py [--triangles 100000]
        [--queries 1000000] [--repeats 3] [--brute 300] [--trimesh 2000] [--json PATH]

The mesh: a 2.5-D terrain (z = a few sines, up to ±1.5 m) over a 200 x 200 m square, Delaunay
triangulation of random points (scipy.spatial; a jittered grid without scipy), about
``--triangles`` NavCels. The queries: points uniform over the square at the terrain's height
plus N(0, 0.3 m), located with :meth:`NavMap.locate` (the NavCel nearest in height along the
vertical, as the original's ``locate_navcel``).

Measured (CPU time of this single-threaded process; the machine is shared): building the
spatial index (:class:`TriangleGrid`, once per map), locating ``--queries`` points (p50 over
``--repeats``), and per query. References: the brute force (every query against every triangle,
:func:`locate_reference`) on ``--brute`` of the queries, scaled to ``--queries`` (and checked
to give the same NavCels), and trimesh's
``proximity.closest_point`` on ``--trimesh`` queries, scaled, when trimesh is installed (the
row says so when it is not). No timing is asserted anywhere. The goals: 1M queries under 10 s
of CPU and at least 100 times faster than the brute force.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.maps.navmap import NavMap, TriangleGrid, locate_reference

SIDE = 200.0


def terrain(xy: np.ndarray) -> np.ndarray:
    """Height of the benchmark terrain at ``xy`` (N, 2)."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.8 * np.sin(x / 9.0) * np.cos(y / 13.0) + 0.5 * np.sin((x + 2 * y) / 23.0) + 0.2 * (
        np.sin(x / 2.1) * np.sin(y / 1.7))


def make_mesh(rng: np.random.Generator, triangles: int) -> tuple[NavMap, str]:
    """A terrain NavMap of about ``triangles`` NavCels and how it was triangulated."""
    try:
        from scipy.spatial import Delaunay
    except ImportError:
        Delaunay = None
    if Delaunay is not None:
        xy = rng.uniform(0.0, SIDE, size=(triangles // 2 + 2, 2))
        faces = Delaunay(xy).simplices
        how = "Delaunay of random points"
    else:
        n = int(math.sqrt(triangles / 2))
        gx, gy = np.meshgrid(np.linspace(0, SIDE, n + 1), np.linspace(0, SIDE, n + 1))
        xy = np.column_stack([gx.ravel(), gy.ravel()])
        inner = (xy > 0).all(axis=1) & (xy < SIDE).all(axis=1)
        xy[inner] += rng.uniform(-0.2, 0.2, size=(inner.sum(), 2)) * SIDE / n
        v = np.arange((n + 1) * (n + 1)).reshape(n + 1, n + 1)
        a, b, c, d = v[:-1, :-1].ravel(), v[:-1, 1:].ravel(), v[1:, 1:].ravel(), v[1:, :-1].ravel()
        faces = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        how = "jittered grid (scipy not installed)"
    return NavMap(np.column_stack([xy, terrain(xy)]), faces), how


def cpu_s(fn) -> tuple[float, object]:
    start = time.process_time()
    out = fn()
    return time.process_time() - start, out


def trimesh_row(navmap: NavMap, queries: np.ndarray, total: int) -> BenchRow:
    """trimesh.proximity.closest_point on ``queries``, scaled to ``total`` queries."""
    label = f"trimesh proximity.closest_point, scaled to {total} queries"
    try:
        import trimesh
    except ImportError:
        return BenchRow(f"{label}: trimesh not installed, not measured", math.nan, "s")
    mesh = trimesh.Trimesh(navmap.vertices, navmap.faces, process=False)
    mesh.nearest  # noqa: B018 - builds its r-tree outside the timing
    seconds, _ = cpu_s(lambda: trimesh.proximity.closest_point(mesh, queries))
    return BenchRow(f"{label} ({len(queries)} measured)", seconds * total / len(queries), "s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--triangles", type=int, default=100_000)
    parser.add_argument("--queries", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--brute", type=int, default=300,
                        help="queries located by brute force (scaled to --queries)")
    parser.add_argument("--trimesh", type=int, default=2000,
                        help="queries given to trimesh (scaled to --queries)")
    add_json_option(parser)
    args = parser.parse_args()

    rng = np.random.default_rng(0)
    navmap, how = make_mesh(rng, args.triangles)
    xy = rng.uniform(0.0, SIDE, size=(args.queries, 2))
    queries = np.column_stack([xy, terrain(xy) + rng.normal(0.0, 0.3, args.queries)])

    build_s, grid = cpu_s(lambda: TriangleGrid(navmap.vertices, navmap.faces))
    navmap._grid = grid  # the index just timed
    times, cids = [], None
    for _ in range(args.repeats):
        seconds, (cids, _) = cpu_s(lambda: navmap.locate(queries))
        times.append(seconds)
    (p50,) = percentiles(times, 50)
    located = float((cids >= 0).mean())

    subset = queries[: args.brute]
    brute_s, (brute_cids, _) = cpu_s(lambda: locate_reference(grid, subset))
    brute_total = brute_s * args.queries / len(subset)
    # The reference evaluates the same candidates with the same rule: exactly the same NavCels.
    agree = float(np.mean(brute_cids == cids[: len(subset)]))

    m = navmap.num_navcels
    rows = [
        BenchRow(f"NavMap.locate, {args.queries} queries, {m} NavCels ({how}), CPU p50", p50, "s",
                 f"brute force (locate_reference, {len(subset)} queries measured), scaled",
                 brute_total, "under 10 s and >= 100x faster than brute force",
                 p50 < 10.0 and brute_total / p50 >= 100.0),
        BenchRow("NavMap.locate per query", p50 / args.queries * 1e6, "us",
                 "brute force per query", brute_s / len(subset) * 1e6),
        BenchRow(f"TriangleGrid build ({grid.nx} x {grid.ny} cells of {grid.cell:.2f} m), CPU",
                 build_s, "s"),
        BenchRow("queries located on a NavCel (fraction)", located, ""),
        BenchRow("same NavCel as the brute force on its subset (fraction)", agree, ""),
    ]
    rows.append(trimesh_row(navmap, queries[: args.trimesh], args.queries))
    ref = rows[-1]
    if not math.isnan(ref.value):
        rows[0] = BenchRow(rows[0].figure, p50, "s", ref.figure, ref.value, rows[0].goal,
                           rows[0].met)
        rows[-1] = BenchRow(ref.figure, ref.value, "s", "brute force, scaled", brute_total)
    report(rows, args.json)


if __name__ == "__main__":
    main()
