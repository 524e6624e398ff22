"""AMCL correction cost for 100 and 1000 particles, beside a reference measured in this run.

    .venv/bin/python packages/easynav-localizers/benchmarks/bench_amcl.py [--repeats 50]

Measured: ``AMCLLocalizer.update`` (the whole correction: fuse the scan into the robot frame,
filter, downsample, score every particle, resample, reseed, estimate, write NavState), on the
shipped house map with a simulated 360-beam scan. Reference: the same scoring written the direct
way, one particle at a time with numpy (the structure of the original C++ loop), so the ratio
shows what the vectorised scoring buys on this machine. No timing is asserted anywhere.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.types import Header, Odometry, Pose, Transform, TransformStamped
from easynav.localizers.amcl_localizer import AMCLLocalizer
from easynav.localizers.particle_filter import likelihood_field
from easynav.maps import SimpleMap, resolve_map_file


def scan(world: SimpleMap, pose, beams=360, max_range=8.0) -> np.ndarray:
    angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
    r = np.arange(0.0, max_range, world.resolution / 2)
    a = angles[:, None] + pose[2]
    occupied = world.occupied_at(pose[0] + r * np.cos(a), pose[1] + r * np.sin(a), outside=True)
    hit = occupied.any(axis=1)
    ranges = r[occupied.argmax(axis=1)][hit]
    return np.column_stack(
        (ranges * np.cos(angles[hit]), ranges * np.sin(angles[hit]), np.full(hit.sum(), 0.0))
    )


def reference_scores(poses, points_xy, world: SimpleMap, field: np.ndarray) -> np.ndarray:
    """One particle at a time (the original's loop structure), numpy per particle."""
    out = np.zeros(len(poses))
    for i, (x, y, yaw) in enumerate(poses):
        c, s = math.cos(yaw), math.sin(yaw)
        wx = x + c * points_xy[:, 0] - s * points_xy[:, 1]
        wy = y + s * points_xy[:, 0] + c * points_xy[:, 1]
        ix, iy = world.world_to_cell(wx, wy)
        inside = world.cells_in_bounds(ix, iy)
        if inside.any():
            out[i] = field[iy[inside], ix[inside]].mean()
    return out


def median_ms(fn, repeats: int) -> tuple[float, float]:
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        samples.append((time.perf_counter() - start) * 1e3)
    samples.sort()
    return statistics.median(samples), samples[int(0.95 * (len(samples) - 1))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=50)
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    rows = []
    world = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    truth = (0.0, 0.0, 0.0)
    points = scan(world, truth)
    print(f"map {world}, scan of {len(points)} points (360 beams)")
    for n in (100, 1000):
        namespace = f"bench_{n}"
        buffer = get_tf_buffer(namespace)
        buffer.set_transform(
            # A laser 0.25 m above the footprint, as on the playground's robot.
            TransformStamped(
                Header(0.0, "base_footprint"), "laser", Transform(np.array([0.0, 0.0, 0.25]))
            ),
            "bench",
            is_static=True,
        )
        amcl = AMCLLocalizer()
        amcl.initialize(
            PluginContext(
                parameters=DictParameters(
                    {"simple.num_particles": n, "simple.initial_pose.std_dev_xy": 0.2}
                ),
                namespace=namespace,
                now=lambda: 1.0,
            ),
            "simple",
        )
        amcl.set_odometry(Odometry(Header(1.0, "odom"), "base_footprint", Pose()))
        nav_state = NavState()
        nav_state.set("map.base", world)
        nav_state.set("laser1", PointPerception(points, "laser", 1.0))
        amcl.update_rt(nav_state)
        amcl.update(nav_state)  # builds the likelihood field once (cached per map)
        p50, p95 = median_ms(lambda a=amcl, s=nav_state: a.update(s), args.repeats)
        field = likelihood_field(world, amcl.hit_sigma)
        poses = amcl.filter.poses.copy()
        cells = np.floor(points / world.resolution)
        downsampled = points[np.unique(cells, axis=0, return_index=True)[1]]
        ref, _ = median_ms(
            lambda p=poses, d=downsampled, f=field: reference_scores(p, d[:, :2], world, f),
            max(5, args.repeats // 5),
        )
        rows.append(
            BenchRow(f"AMCL correction, {n} particles, p50", p50, "ms",
                     "per-particle numpy loop, p50", ref,
                     goal="faster than the per-particle loop", met=p50 < ref)
        )
        rows.append(BenchRow(f"AMCL correction, {n} particles, p95", p95, "ms"))
    report(rows, args.json)


if __name__ == "__main__":
    main()
