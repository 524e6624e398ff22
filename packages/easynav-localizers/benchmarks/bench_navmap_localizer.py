"""NavMap AMCL: correction and prediction times, scoring beside the original's loop (same run).

    .venv/bin/python packages/easynav-localizers/benchmarks/bench_navmap_localizer.py [--json PATH]

Input: the two-level room of ``tests/test_navmap_localizer.py`` (10 × 6 m, an upper floor at
1.5 m over part of the ground floor, a ramp; NavMap of 0.25 m quads, Bonxai map at 0.1 m), a 3D
lidar scan ray-cast on the upper floor, particles around the robot. Measured:

- ``NavMapAMCLLocalizer.update``: the whole correction (per-sensor downsampling, TF, scoring
  with ray occlusion on the inflated map, weights, estimate, NavState) for 100 and 500 particles;
- ``update_rt``: the prediction (motion along the surface, NavMap point location);
- the scoring alone (inflation σ 0.05 m): compiled (:func:`score_particles` with numba) beside
  its numpy version (vectorised over particles, points and ray steps), 300 particles × 120
  points (the integration matrix's NavMap AMCL settings); the numpy version beside
  :func:`score_reference` (the original's loop, one particle, one point and one ray step at a
  time), 20 particles.

Goals: a correction of the default 100 particles within a 10 Hz non-RT cycle (<= 100 ms), a
prediction of 100 particles <= 2 ms, and the compiled scoring at least 5× faster than the numpy
one. Medians over ``--repeats`` runs, CPU time of this process.
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
    inflated = InflatedVoxelMap(world.VOXELS, 0.05, 0.01)
    rng = np.random.default_rng(0)
    scan = world.ray_cast(world.VOXELS, (7.0, 4.0, 1.8), 0.3, rng) + (0.0, 0.0, 0.3)
    rows += compiled_beside_numpy(inflated, scan, rng, args.repeats)
    rows += numpy_beside_the_loop(inflated, scan, args.repeats)
    report(rows, args.json)


def particles_around_truth(count: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """Rotations and translations of ``count`` particles around :data:`TRUTH`."""
    yaws = TRUTH[3] + rng.normal(0.0, 0.1, count)
    rot = attitudes(yaws, np.tile((0.0, 0.0, 1.0), (count, 1)))
    trans = np.column_stack((TRUTH[0] + rng.normal(0.0, 0.3, count),
                             TRUTH[1] + rng.normal(0.0, 0.3, count), np.full(count, TRUTH[2])))
    return rot, trans


def compiled_beside_numpy(inflated, scan, rng, repeats: int) -> list[BenchRow]:
    """The compiled scoring beside the numpy one, 300 particles × 120 points."""
    points = scan[rng.choice(len(scan), min(120, len(scan)), replace=False)]
    origins = np.tile((0.0, 0.0, 0.3), (len(points), 1))
    rot, trans = particles_around_truth(300, rng)
    compiled = score_particles(inflated, rot, trans, points, origins)  # compiles (or loads)
    vectorised = score_particles(inflated, rot, trans, points, origins, compiled=False)
    ours, = percentiles(timed(lambda: score_particles(inflated, rot, trans, points, origins),
                              repeats), 50)
    ref, = percentiles(timed(lambda: score_particles(inflated, rot, trans, points, origins,
                                                     compiled=False), repeats), 50)
    diff = float(np.abs(compiled - vectorised).max())
    return [
        BenchRow(f"scoring, compiled, 300 particles × {len(points)} points, median", ours, "ms",
                 "the numpy version (vectorised over particles, points, ray steps)", ref,
                 goal=">= 5× faster than numpy", met=bool(ours * 5.0 <= ref)),
        BenchRow("scoring: largest difference, compiled to numpy", diff, "",
                 goal="<= 1e-9 (summation order)", met=bool(diff <= 1e-9)),
    ]


def numpy_beside_the_loop(inflated, scan, repeats: int) -> list[BenchRow]:
    """The numpy scoring beside the original's loop, 20 particles × the whole scan."""
    origins = np.tile((0.0, 0.0, 0.3), (len(scan), 1))
    rot, trans = particles_around_truth(20, np.random.default_rng(1))
    ours, = percentiles(timed(lambda: score_particles(inflated, rot, trans, scan, origins,
                                                      compiled=False), repeats), 50)
    ref, = percentiles(timed(lambda: score_reference(inflated, rot, trans, scan, origins), 2),
                       50)
    diff = float(np.abs(score_particles(inflated, rot, trans, scan, origins, compiled=False)
                        - score_reference(inflated, rot, trans, scan, origins)).max())
    return [
        BenchRow(f"scoring, numpy, 20 particles × {len(scan)} points, median", ours, "ms",
                 "the original's loop (per particle, point, ray step)", ref),
        BenchRow("scoring: largest difference, numpy to the loop", diff, "",
                 goal="<= 1e-9 (summation order)", met=bool(diff <= 1e-9)),
    ]


if __name__ == "__main__":
    main()
