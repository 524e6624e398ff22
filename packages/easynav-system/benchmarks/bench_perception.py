"""Benchmark: perceptions and TF on the paths the RT and non-RT loops take.

Prints, each with its goal and a reference measured in the same run:
  1. a 1080-beam LaserScan to points, fused to the map frame and downsampled (goal <= 0.5 ms);
  2. a 100k-point PointCloud2 converted, fused to the map frame and downsampled
     (goal <= 15 ms), beside open3d's voxel downsample of the same cloud (optional dependency:
     pip install open3d-cpu; Debian needs libusb-1.0-0);
  3. a TF lookup through a 3-frame chain (goal <= 20 us), beside the same composition done
     with numpy 4x4 matrices.
Each figure: median and p90 wall time, and median CPU time of this thread (on a loaded machine
the CPU time is what the code costs). The cloud pipeline is measured again with glibc malloc
told to keep freed memory, to show the cost of page faults (see tune_malloc).

Run: .venv/bin/python packages/easynav-system/benchmarks/bench_perception.py [--repeat N]
"""

from __future__ import annotations

import argparse
import math
import resource
import statistics
import time
from collections.abc import Callable

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import TFBuffer
from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.system.process_tuning import tune_malloc
from easynav.system.sensors.converters import points_from_point_cloud2
from easynav.system.sensors.handlers import LaserScanHandler, PointCloud2Handler

RESOLUTION = 0.1


def timed(fn: Callable[[], object], repeat: int, warmup: int = 5) -> tuple[float, float, float]:
    """Median and 90th percentile of ``fn``'s wall time, and the median of its CPU time (s).

    The CPU time (this thread only) leaves out the time other processes took the core: on a
    shared, loaded machine it is the figure that says what the code itself costs.
    """
    for _ in range(warmup):
        fn()
    wall = []
    cpu = []
    for _ in range(repeat):
        c0 = time.thread_time()
        w0 = time.perf_counter()
        fn()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.thread_time() - c0)
    wall.sort()
    return statistics.median(wall), wall[int(0.9 * (len(wall) - 1))], statistics.median(cpu)


def robot_tf() -> TFBuffer:
    """map -> odom (dynamic, 100 Hz for 10 s), odom -> base_footprint (dynamic), -> laser."""
    buffer = TFBuffer()
    for i in range(1001):
        t = 1000.0 + i * 0.01
        drift = (0.01 * i, 0.5, 0.0, 0.0, 0.0, math.sin(0.001 * i), math.cos(0.001 * i))
        buffer.set_transform_values("map", "odom", t, drift, "bench")
        yaw = 0.002 * i
        buffer.set_transform_values(
            "odom", "base_footprint", t,
            (0.02 * i, 0.01 * i, 0.0, 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)), "bench",
        )  # fmt: skip
    buffer.set_transform_values(
        "base_footprint", "laser", 0.0, (0.2, 0.0, 0.3, 0.0, 0.0, 0.0, 1.0), "bench", True
    )
    buffer.set_transform_values(
        "base_footprint", "lidar", 0.0, (0.0, 0.0, 0.8, 0.0, 0.0, 0.0, 1.0), "bench", True
    )
    return buffer


def make_scan(stamp: float):
    from sensor_msgs.msg import LaserScan

    rng = np.random.default_rng(0)
    n = 1080
    msg = LaserScan()
    msg.header.frame_id = "laser"
    msg.header.stamp.sec = int(stamp)
    msg.header.stamp.nanosec = int(round((stamp % 1) * 1e9))
    msg.angle_min = -3 * math.pi / 4
    msg.angle_increment = 1.5 * math.pi / n
    msg.angle_max = msg.angle_min + msg.angle_increment * (n - 1)
    msg.range_min, msg.range_max = 0.05, 30.0
    ranges = rng.uniform(0.5, 12.0, n).astype(np.float32)
    ranges[rng.choice(n, 40, replace=False)] = np.inf  # no return, as real scans have
    msg.ranges = ranges.tolist()
    return msg


def room_cloud(n_rings: int = 64, n_azimuth: int = 1563) -> np.ndarray:
    """A 3D lidar at the centre of a 20 x 14 x 3 m room: ~100k points on walls, floor, ceiling."""
    elevation = np.radians(np.linspace(-25.0, 15.0, n_rings))[:, None]
    azimuth = np.linspace(-math.pi, math.pi, n_azimuth, endpoint=False)[None, :]
    d = np.stack(
        np.broadcast_arrays(
            np.cos(elevation) * np.cos(azimuth),
            np.cos(elevation) * np.sin(azimuth),
            np.sin(elevation),
        ),
        axis=-1,
    ).reshape(-1, 3)
    bounds_low = np.array([-10.0, -7.0, -0.8])
    bounds_high = np.array([10.0, 7.0, 2.2])
    with np.errstate(divide="ignore"):
        t_high = np.where(d > 0, bounds_high / d, np.inf)
        t_low = np.where(d < 0, bounds_low / d, np.inf)
    ranges = np.minimum(t_high, t_low).min(axis=1)
    noise = np.random.default_rng(1).normal(0.0, 0.01, ranges.shape)
    return d * (ranges + noise)[:, None]


def make_cloud_msg(points: np.ndarray, stamp: float):
    from sensor_msgs.msg import PointCloud2, PointField

    n = points.shape[0]
    record = np.zeros(n, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4")])
    record["x"], record["y"], record["z"] = points.T
    record["intensity"] = 100.0
    msg = PointCloud2()
    msg.header.frame_id = "lidar"
    msg.header.stamp.sec = int(stamp)
    msg.header.stamp.nanosec = int(round((stamp % 1) * 1e9))
    msg.height, msg.width = 1, n
    msg.fields = [
        PointField(name=name, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, name in enumerate(("x", "y", "z", "intensity"))
    ]
    msg.point_step, msg.row_step = 16, 16 * n
    msg.is_bigendian, msg.is_dense = False, True
    msg.data = record.tobytes()
    return msg


def numpy_chain_lookup(mats: list[np.ndarray]) -> np.ndarray:
    """Reference: the same 3-frame composition with 4x4 numpy matrices (no interpolation)."""
    return mats[0] @ mats[1] @ mats[2]


def fmt(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:8.1f} us"
    return f"{seconds * 1e3:8.2f} ms"


ROWS: list[BenchRow] = []


def line(
    label: str,
    figures: tuple[float, float, float],
    goal: float | None = None,
    reference: tuple[str, tuple[float, float, float]] | None = None,
) -> None:
    """Print one figure and keep it as a row (median wall time; the reference's median)."""
    median, p90, cpu = figures
    unit, scale = ("µs", 1e6) if median < 1e-3 else ("ms", 1e3)
    ROWS.append(
        BenchRow(
            f"{label}, median",
            median * scale,
            unit,
            reference[0] if reference else "",
            reference[1][0] * scale if reference else float("nan"),
            goal=f"<= {fmt(goal).strip()}" if goal is not None else "",
            met=(median <= goal) if goal is not None else None,
        )
    )
    verdict = ""
    if goal is not None:
        verdict = f"  goal <= {fmt(goal).strip()}: {'met' if median <= goal else 'MISSED'}"
        if median > goal and cpu <= goal:
            verdict += " (CPU time met: machine loaded)"
    print(f"  {label:<50} median {fmt(median)} p90 {fmt(p90)} cpu {fmt(cpu)}{verdict}")


def main() -> None:
    import os

    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=200, help="timed runs per figure")
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    repeat = args.repeat
    buffer = robot_tf()
    stamp = 1005.005  # between two TF samples: interpolation on the two dynamic frames

    print("1. LaserScan, 1080 beams -> points -> fuse to map -> downsample 0.1 m")
    scan = make_scan(stamp)
    handler = LaserScanHandler()

    def scan_pipeline():
        perception = handler.to_perception(scan, "laser1")
        return (
            PointPerceptionsOps({"laser1": perception}, tf_buffer=buffer)
            .fuse("map")
            .downsample(RESOLUTION)
            .as_points()
        )

    n_out = scan_pipeline().shape[0]
    convert = timed(lambda: handler.to_perception(scan, "laser1"), repeat)
    whole = timed(scan_pipeline, repeat)
    line("convert only", convert)
    line(f"convert + fuse + downsample ({n_out} points out)", whole, goal=0.5e-3)

    print("2. PointCloud2, 100k points -> points -> fuse to map -> downsample 0.1 m")
    pts = room_cloud()
    cloud = make_cloud_msg(pts, stamp)
    cloud_handler = PointCloud2Handler()

    def cloud_pipeline():
        perception = cloud_handler.to_perception(cloud, "lidar")
        return (
            PointPerceptionsOps({"lidar": perception}, tf_buffer=buffer)
            .fuse("map")
            .downsample(RESOLUTION)
            .as_points()
        )

    cloud_repeat = max(10, repeat // 5)
    n_out = cloud_pipeline().shape[0]
    converted = points_from_point_cloud2(cloud)[0]
    convert = timed(lambda: points_from_point_cloud2(cloud), cloud_repeat)
    fused = (
        PointPerceptionsOps([PointPerception(converted, "lidar", stamp)], tf_buffer=buffer)
        .fuse("map")
        .as_points()
    )
    downsample = timed(
        lambda: (
            PointPerceptionsOps([PointPerception(fused, "map", stamp)])
            .downsample(RESOLUTION)
            .as_points()
        ),
        cloud_repeat,
    )
    faults_before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    whole = timed(cloud_pipeline, cloud_repeat)
    faults = (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults_before) / (
        cloud_repeat + 5
    )
    line(f"convert only ({converted.shape[0]} points)", convert)
    line("voxel downsample only (EasyNav, numpy)", downsample)
    line(f"convert + fuse + downsample ({n_out} points out)", whole, goal=15e-3)
    print(f"  page faults per pipeline run: {faults:.0f}")
    if tune_malloc():
        faults_before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        tuned = timed(cloud_pipeline, cloud_repeat)
        faults = (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults_before) / (
            cloud_repeat + 5
        )
        line("same, glibc malloc keeping freed memory (mallopt)", tuned, goal=15e-3)
        print(f"  page faults per pipeline run: {faults:.0f}")
    try:
        import open3d as o3d
    except Exception as exc:  # optional: report why instead of a figure
        print(f"  open3d voxel_down_sample: not available ({type(exc).__name__}: {exc})")
    else:
        o3d_cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(fused))
        o3d_only = timed(lambda: o3d_cloud.voxel_down_sample(RESOLUTION), cloud_repeat)

        def o3d_with_copy():
            c = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(fused))
            return np.asarray(c.voxel_down_sample(RESOLUTION).points)

        o3d_copy = timed(o3d_with_copy, cloud_repeat)
        o3d_n = len(o3d_cloud.voxel_down_sample(RESOLUTION).points)
        line(f"open3d {o3d.__version__} voxel_down_sample ({o3d_n} points out)", o3d_only)
        ROWS.append(
            BenchRow("voxel downsample of the 100k cloud, CPU median", downsample[2] * 1e3, "ms",
                     f"open3d {o3d.__version__} voxel_down_sample, CPU median",
                     o3d_only[2] * 1e3)
        )
        line("open3d incl. numpy -> open3d -> numpy copies", o3d_copy)
        print(
            f"  ratio EasyNav downsample / open3d voxel_down_sample: "
            f"{downsample[2] / o3d_only[2]:.2f} (CPU; open3d averages each voxel, EasyNav "
            "keeps the first point)"
        )

    print("3. TF lookup map <- laser through odom and base_footprint (3 transforms)")
    values = timed(lambda: buffer.lookup_transform_values("map", "laser", stamp), repeat * 50)
    full = timed(lambda: buffer.lookup_transform("map", "laser", stamp), repeat * 50)
    latest = timed(lambda: buffer.lookup_transform("map", "laser"), repeat * 50)
    from scipy.spatial.transform import Rotation

    mats = []
    for parent, child in (("map", "odom"), ("odom", "base_footprint"), ("base_footprint", "laser")):
        _, (tx, ty, tz, qx, qy, qz, qw) = buffer.lookup_transform_values(parent, child, stamp)
        m = np.eye(4)
        m[:3, :3] = Rotation.from_quat((qx, qy, qz, qw)).as_matrix()
        m[:3, 3] = (tx, ty, tz)
        mats.append(m)
    reference = timed(lambda: numpy_chain_lookup(mats), repeat * 50)
    chain = ("3 numpy 4x4 matmuls", reference)
    line("lookup_transform at a stamp (interpolated)", full, goal=20e-6, reference=chain)
    line("lookup_transform latest", latest, goal=20e-6, reference=chain)
    line("lookup_transform_values at a stamp (no arrays)", values)
    line("reference: 3 numpy 4x4 matmuls, no lookup/interp.", reference)
    print(f"  ratio lookup_transform / numpy matmul reference: {full[2] / reference[2]:.2f} (CPU)")
    print()
    report(ROWS, args.json)


if __name__ == "__main__":
    main()
