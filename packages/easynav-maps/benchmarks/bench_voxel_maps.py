"""Inserting a 20k-point cloud with ray casting: the Bonxai-style map against OctoMap.

    .venv/bin/python packages/easynav-maps/benchmarks/bench_voxel_maps.py [--repeats 10]
        [--resolution 0.1] [--run-minutes 5] [--json PATH]

Measured, on the same input in the same run and at the same resolution: the CPU time of one
``insert_point_cloud`` of the same 20,000-point cloud (a lidar-like scan of a 16 x 12 x 3 m room
with furniture, beams from the sensor origin to every point, free voxels cleared, each voxel
updated once) into :class:`BonxaiMap` (written here, ray walk compiled with numba) and into an
OctoMap ``OcTree`` (pyoctomap, C++), each into a map already holding that room; then the memory
of both maps after a ``--run-minutes`` run: the playground's 3D lidar (16 rings x 180 beams, 5 Hz,
as in the furnished_office world) inserted at the maps managers' 5 Hz (params/octomap.params.yaml,
bonxai.params.yaml) from a robot driving laps through the room at 0.5 m/s, into both maps at the
same resolution; memory as each map counts it (Bonxai-style: its blocks and index; OctoMap:
``memoryUsage()``), after the first minute and at the end. CPU time of this single-threaded
process (the machine is shared). No timing is asserted anywhere. The goal: no slower than OctoMap.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.maps.voxel.bonxai_map import BonxaiMap
from easynav.maps.voxel.voxel_rays import numba_available, warm_up

ROOM = (16.0, 12.0, 3.0)


def room_scan(rng: np.random.Generator, origin: np.ndarray, count: int) -> np.ndarray:
    """``count`` points where beams from ``origin`` in random directions meet the room's walls,
    floor, ceiling or one of a few boxes (furniture)."""
    direction = rng.normal(size=(count, 3))
    direction[:, 2] *= 0.4  # a lidar looks mostly sideways
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    size = np.array(ROOM)
    with np.errstate(divide="ignore"):
        t_wall = np.where(direction > 0, (size - origin) / direction, -origin / direction)
    t = t_wall.min(axis=1)
    boxes = [((4.0, 3.0, 0.0), (5.0, 4.0, 0.8)), ((10.0, 7.0, 0.3), (11.5, 7.5, 0.4)),
             ((12.0, 2.0, 0.7), (13.6, 3.2, 0.75))]
    for low, high in boxes:
        with np.errstate(divide="ignore", invalid="ignore"):
            t0 = (np.array(low) - origin) / direction
            t1 = (np.array(high) - origin) / direction
        near = np.nan_to_num(np.minimum(t0, t1), nan=np.inf).max(axis=1)
        far = np.nan_to_num(np.maximum(t0, t1), nan=-np.inf).min(axis=1)
        hit = (near <= far) & (far > 0) & (near > 0)
        t = np.where(hit & (near < t), near, t)
    return origin + direction * t[:, None] + rng.normal(0.0, 0.01, (count, 3))


def cpu_ms(fn) -> float:
    start = time.process_time()
    fn()
    return (time.process_time() - start) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    parser.add_argument("--resolution", type=float, default=0.1)
    parser.add_argument("--run-minutes", type=float, default=5.0,
                        help="length of the simulated run whose maps are measured")
    parser.add_argument("--rate", type=float, default=5.0, help="clouds inserted per second")
    parser.add_argument("--run-points", type=int, default=16 * 180,
                        help="points per cloud in the run (the playground's 3D lidar)")
    parser.add_argument("--points", type=int, default=20000)
    add_json_option(parser)
    args = parser.parse_args()
    try:
        from easynav.maps.voxel.octomap_map import OctomapMap
    except ImportError as exc:  # pragma: no cover
        raise SystemExit(f"bench_voxel_maps: {exc}") from None
    import pyoctomap

    warm_up()
    rng = np.random.default_rng(0)
    origin = np.array([8.0, 6.0, 0.45])
    cloud = room_scan(rng, origin, args.points)
    res = args.resolution

    # Each map first holds the room (one insertion), then the same cloud is timed again and
    # again: the steady state of a map being updated, not the first allocation.
    bonxai = BonxaiMap(res)
    bonxai.insert_point_cloud(cloud, origin)
    tree = pyoctomap.OcTree(res)
    tree.insertPointCloud(cloud, origin, max_range=-1.0)
    # Same voxels occupied: the two do the same work (checked, not assumed).
    octo_check = OctomapMap(res)
    octo_check.insert_point_cloud(cloud, origin)
    same = np.array_equal(np.sort(octo_check.occupied_keys()), np.sort(bonxai.occupied_keys()))
    bonxai_ms, octo_ms = [], []
    for _ in range(args.repeats):
        bonxai_ms.append(cpu_ms(lambda: bonxai.insert_point_cloud(cloud, origin)))
        octo_ms.append(cpu_ms(lambda: tree.insertPointCloud(cloud, origin, max_range=-1.0)))
    b50, b99 = percentiles(bonxai_ms, 50, 99)
    o50, o99 = percentiles(octo_ms, 50, 99)

    # Memory after a run: the robot drives laps of an ellipse through the room at 0.5 m/s, its
    # lidar inserted at --rate into both maps.
    bonxai_run, octo_run = BonxaiMap(res), pyoctomap.OcTree(res)
    clouds = int(round(args.run_minutes * 60.0 * args.rate))
    lap = 2.0 * math.pi * math.sqrt((5.0**2 + 4.0**2) / 2.0)  # ellipse perimeter (approx.), m
    after_minute = None
    for k in range(clouds):
        angle = 2.0 * math.pi * (0.5 * k / args.rate) / lap
        sensor = np.array([8.0 + 5.0 * math.cos(angle), 6.0 + 4.0 * math.sin(angle), 0.45])
        scan = room_scan(rng, sensor, args.run_points)
        bonxai_run.insert_point_cloud(scan, sensor)
        octo_run.insertPointCloud(scan, sensor, max_range=-1.0)
        if k + 1 == int(round(60.0 * args.rate)):
            after_minute = (bonxai_run.memory_bytes() / 1e6, octo_run.memoryUsage() / 1e6)
    bonxai_mb = bonxai_run.memory_bytes() / 1e6
    octo_mb = octo_run.memoryUsage() / 1e6
    path = "numba" if numba_available() else "Python (numba not installed)"
    rows = [
        BenchRow(
            f"BonxaiMap.insert_point_cloud, {args.points} points, {res} m, CPU p50 [{path}]",
            b50, "ms", "OctoMap OcTree.insertPointCloud (pyoctomap), CPU p50", o50,
            "no slower than OctoMap", b50 <= o50,
        ),
        BenchRow(
            f"BonxaiMap.insert_point_cloud, {args.points} points, {res} m, CPU p99", b99, "ms",
            "OctoMap, CPU p99", o99,
        ),
        BenchRow(
            f"memory of the map after a {args.run_minutes:g}-minute run ({clouds} clouds of "
            f"{args.run_points} points, {res} m)", bonxai_mb, "MB",
            "OctoMap memoryUsage(), same run", octo_mb,
        ),
        BenchRow("same occupied voxels as OctoMap after one cloud (1 = yes)", float(same), ""),
    ]
    if after_minute is not None:
        rows.append(BenchRow(
            "memory of the map after the run's first minute", after_minute[0], "MB",
            "OctoMap memoryUsage(), same run", after_minute[1],
        ))
    report(rows, args.json)


if __name__ == "__main__":
    main()
