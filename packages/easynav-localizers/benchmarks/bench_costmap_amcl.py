"""Costmap AMCL correction, 2000 particles × 60 beams, beside a per-particle loop (same run).

    .venv/bin/python packages/easynav-localizers/benchmarks/bench_costmap_amcl.py [--json PATH]

Input: the shipped house map as a Costmap2D (walls lethal), a 60-beam scan simulated at a known
pose, 2000 particles around it. Measured, for both sensor models:

- ``CostmapAMCLLocalizer.update``: the whole correction (fuse the scan into the footprint frame,
  filter, downsample, score every particle, weigh, resample, estimate, write NavState);
- the scoring alone (:func:`hit_fractions`: the numba loop, and the vectorised numpy version
  that runs without numba).

Reference: the same scoring written the direct way, one particle at a time with numpy (the
structure of the original's C++ loop), in the same run. Goal (issue #14): the correction of
2000 particles × 60 beams in <= 5 ms. Medians and p99 over ``--repeats`` runs, CPU time of
this process.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Costmap2D, Header, Odometry, Pose, Transform, TransformStamped
from easynav.localizers.costmap_amcl_localizer import CostmapAMCLLocalizer
from easynav.localizers.costmap_sampling import beam_likelihood_field
from easynav.localizers.particle_filter import hit_fractions
from easynav.maps import SimpleMap, resolve_map_file

PARTICLES = 2000
BEAMS = 60


def house() -> Costmap2D:
    world = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    return Costmap2D(np.where(world.cells, 254, 0).astype(np.uint8), world.resolution,
                     world.origin_x, world.origin_y)


def scan(costmap: Costmap2D, pose, beams=BEAMS, max_range=8.0) -> np.ndarray:
    angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
    r = np.arange(0.0, max_range, costmap.resolution / 2)
    a = angles[:, None] + pose[2]
    hit_cells = costmap.cost_at(pose[0] + r * np.cos(a), pose[1] + r * np.sin(a)) == 254
    hit = hit_cells.any(axis=1)
    ranges = r[hit_cells.argmax(axis=1)][hit]
    return np.column_stack(
        (ranges * np.cos(angles[hit]), ranges * np.sin(angles[hit]), np.zeros(hit.sum()))
    )


def reference_scores(poses, points_xy, costmap: Costmap2D, field: np.ndarray) -> np.ndarray:
    """One particle at a time (the original's loop structure), numpy per particle."""
    out = np.zeros(len(poses))
    for i, (x, y, yaw) in enumerate(poses):
        c, s = math.cos(yaw), math.sin(yaw)
        wx = x + c * points_xy[:, 0] - s * points_xy[:, 1]
        wy = y + s * points_xy[:, 0] + c * points_xy[:, 1]
        ix, iy = costmap.world_to_cell(wx, wy)
        inside = costmap.in_bounds(ix, iy)
        if inside.any():
            out[i] = field[iy[inside], ix[inside]].mean()
    return out


def timed(fn, repeats: int) -> list[float]:
    # CPU time of this process (single-threaded work): on a shared machine the wall clock also
    # measures the neighbours' load.
    samples = []
    for _ in range(repeats):
        start = time.process_time()
        fn()
        samples.append((time.process_time() - start) * 1e3)
    return samples


def localizer(model: str, costmap: Costmap2D, points: np.ndarray, truth):
    namespace = f"bench_costmap_amcl_{model}"
    get_tf_buffer(namespace).set_transform(
        TransformStamped(Header(0.0, "base_footprint"), "laser",
                         Transform(np.array([0.0, 0.0, 0.25]))),
        "bench", is_static=True,
    )
    amcl = CostmapAMCLLocalizer()
    amcl.initialize(
        PluginContext(
            parameters=DictParameters({
                "amcl.num_particles": PARTICLES, "amcl.sensor_model": model,
                "amcl.initial_pose.x": truth[0], "amcl.initial_pose.y": truth[1],
                "amcl.initial_pose.std_dev_xy": 0.3, "amcl.reseed_freq": 1e-3,
            }),
            namespace=namespace,
            now=lambda: 1.0,
        ),
        "amcl",
    )
    amcl.set_odometry(Odometry(Header(1.0, "odom"), "base_footprint", Pose()))
    nav_state = NavState()
    nav_state.set("map.base", costmap)
    nav_state.set("laser", PointPerception(points, "laser", 1.0))
    amcl.update_rt(nav_state)
    amcl.update(nav_state)  # builds the sensor tables once (cached per map)
    return amcl, nav_state


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=100)
    add_json_option(parser)
    args = parser.parse_args()
    costmap = house()
    truth = (0.0, 0.0, 0.0)
    points = scan(costmap, truth)
    print(f"house costmap {costmap.width}x{costmap.height} at {costmap.resolution} m, "
          f"{PARTICLES} particles, scan of {len(points)} points ({BEAMS} beams)")
    rows = []
    poses = None
    for model in ("hit_count", "likelihood_field"):
        amcl, nav_state = localizer(model, costmap, points, truth)
        p50, p99 = percentiles(timed(lambda a=amcl, s=nav_state: a.update(s), args.repeats),
                               50, 99)
        poses = amcl.filter.poses.copy()
        rows.append(BenchRow(f"costmap AMCL correction ({model}), median", p50, "ms",
                             goal="<= 5 ms", met=bool(p50 <= 5.0)))
        rows.append(BenchRow(f"costmap AMCL correction ({model}), p99", p99, "ms"))
    field, _ = beam_likelihood_field(costmap, 0.2, 0.5, 0.5, 10.0, 2.0)
    xy = points[:, :2]
    ours, _ = percentiles(timed(lambda: hit_fractions(poses, xy, costmap, field), args.repeats),
                          50, 99)
    vectorised, _ = percentiles(
        timed(lambda: hit_fractions(poses, xy, costmap, field, compiled=False), args.repeats),
        50, 99,
    )
    ref, _ = percentiles(
        timed(lambda: reference_scores(poses, xy, costmap, field), max(5, args.repeats // 10)),
        50, 99,
    )
    check = np.abs(hit_fractions(poses, xy, costmap, field)[0]
                   - reference_scores(poses, xy, costmap, field)).max()
    rows.append(BenchRow("scoring alone (likelihood field, numba), median", ours, "ms",
                         "per-particle numpy loop", ref))
    rows.append(BenchRow("scoring alone (vectorised numpy, no numba), median", vectorised, "ms",
                         "per-particle numpy loop", ref))
    rows.append(BenchRow("scoring: largest difference to the loop", float(check), "",
                         goal="<= 1e-5 (float32 cell arithmetic)", met=bool(check <= 1e-5)))
    report(rows, args.json)


if __name__ == "__main__":
    main()
