"""NavMap AMCL: correction and prediction times, scoring beside the original's loop (same run).

    .venv/bin/python packages/easynav-localizers/benchmarks/bench_navmap_localizer.py [--json PATH]

Input: the two-level room of ``tests/test_navmap_localizer.py`` (10 × 6 m, an upper floor at
1.5 m over part of the ground floor, a ramp; NavMap of 0.25 m quads, Bonxai map at 0.1 m), a 3D
lidar scan ray-cast on the upper floor, particles around the robot. Measured:

- ``NavMapAMCLLocalizer.update``: the whole correction (per-sensor downsampling, TF, scoring
  with ray occlusion on the inflated map, weights, estimate, NavState) for 100 and 500 particles;
- ``update_rt``: the prediction (motion along the surface, NavMap point location);
- the scoring alone (:func:`score_particles`, vectorised) beside :func:`score_reference` (the
  original's loop, one particle, one point and one ray step at a time), 20 particles.

Goals: a correction of the default 100 particles within a 10 Hz non-RT cycle (<= 100 ms) and a
prediction of 100 particles <= 2 ms. Medians over ``--repeats`` runs, CPU time of this process.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import test_navmap_localizer as world  # noqa: E402 - the tests' world, not a copy

from easynav.localizers.navmap_amcl_localizer import attitudes  # noqa: E402
from easynav.localizers.navmap_voxel_scoring import (  # noqa: E402
    InflatedVoxelMap,
    score_particles,
    score_reference,
)

TRUTH = (7.0, 4.0, 1.5, 0.3)


def timed(fn, repeats: int) -> list[float]:
    samples = []
    for _ in range(repeats):
        start = time.process_time()
        fn()
        samples.append((time.process_time() - start) * 1e3)
    return samples


def localizer(particles: int):
    sim = world.Sim({"num_particles": particles, "initial_pose.x": TRUTH[0],
                     "initial_pose.y": TRUTH[1], "initial_pose.z": TRUTH[2],
                     "initial_pose.std_dev_xy": 0.3, "reseed_freq": 1e-3})
    sim.move(0.0)
    sim.scan(TRUTH)  # builds map.bonxai.inflated once
    return sim


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    add_json_option(parser)
    args = parser.parse_args()
    rows = []
    for particles in (100, 500):
        sim = localizer(particles)
        points = sim.amcl.last_points_used
        p50, = percentiles(timed(lambda s=sim: s.amcl.update(s.nav_state), args.repeats), 50)
        goal = {"goal": "<= 100 ms", "met": bool(p50 <= 100.0)} if particles == 100 else {}
        rows.append(BenchRow(f"correction, {particles} particles × {points} points, median",
                             p50, "ms", **goal))
        p50, = percentiles(timed(lambda s=sim: s.move(0.02), args.repeats), 50)
        goal = {"goal": "<= 2 ms", "met": bool(p50 <= 2.0)} if particles == 100 else {}
        rows.append(BenchRow(f"prediction, {particles} particles, median", p50, "ms", **goal))
    sim = localizer(20)
    inflated = InflatedVoxelMap(world.VOXELS, 0.05, 0.01)
    rng = np.random.default_rng(0)
    points = world.ray_cast(world.VOXELS, (7.0, 4.0, 1.8), 0.3, rng) + (0.0, 0.0, 0.3)
    origins = np.tile((0.0, 0.0, 0.3), (len(points), 1))
    poses = sim.amcl.filter.poses
    rot = attitudes(poses[:, 2], np.tile((0.0, 0.0, 1.0), (len(poses), 1)))
    trans = np.column_stack((poses[:, :2], np.full(len(poses), 1.5)))
    ours, = percentiles(timed(lambda: score_particles(inflated, rot, trans, points, origins),
                              args.repeats), 50)
    ref, = percentiles(timed(lambda: score_reference(inflated, rot, trans, points, origins), 2),
                       50)
    diff = float(np.abs(score_particles(inflated, rot, trans, points, origins)
                        - score_reference(inflated, rot, trans, points, origins)).max())
    rows.append(BenchRow(f"scoring alone, 20 particles × {len(points)} points, median", ours,
                         "ms", "the original's loop (per particle, point, ray step)", ref))
    rows.append(BenchRow("scoring: largest difference to the loop", diff, "",
                         goal="<= 1e-9 (summation order)", met=bool(diff <= 1e-9)))
    report(rows, args.json)


if __name__ == "__main__":
    main()
