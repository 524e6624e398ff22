"""RunMonitor: the demo's ROS node, watching the robot and EasyNav during a run."""

from __future__ import annotations

import json
import math
import threading

import numpy as np
from easynav_interfaces.msg import GoalManagerInfo, Heartbeat
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from nav_msgs.msg import Path as PathMsg
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from easynav.core.types import quaternion_to_yaw
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.system.goals.ros_conversion import goal_topics_qos
from easynav.system.ros.converters import time_from_msg


def _yaw(q) -> float:
    return quaternion_to_yaw(q.x, q.y, q.z, q.w)


def compose(a: tuple[float, float, float], b: tuple[float, float, float]):
    """Planar pose composition ``a * b`` of ``(x, y, yaw)`` tuples."""
    ax, ay, ayaw = a
    bx, by, byaw = b
    c, s = math.cos(ayaw), math.sin(ayaw)
    return (ax + c * bx - s * by, ay + s * bx + c * by, ayaw + byaw)


class RunMonitor(Node):
    """Subscribes what the demo reports on, with ``use_sim_time`` (stamps are simulated time).

    - ``ground_truth``: the true pose and speed (live progress): only the latest one is kept
      (depth 1), so a busy process reads where the robot is, not where it was a hundred
      messages ago (the complete trajectory is the playground's record);
    - ``/tf``: ``map -> odom`` (from EasyNav's localizer) composed with ``odom ->
      base_footprint`` (from the playground) gives EasyNav's pose estimate at each odometry
      stamp, recorded in :attr:`estimates` for the localisation error;
    - ``estimate_topic`` instead, when given: the localizer's pose (an Odometry in the map
      frame) for a localizer scored from its own topic (the GpsLocalizer: the original's
      map -> odom was a static identity, and composing it with odometry scored the odometry;
      ours follows the estimate, and its topic is the estimate itself);
    - with a ``frame_prefix`` (one robot of several, the node in the robot's namespace): its
      own ``tf`` (``/r1/tf``) instead, the frames prefixed (``r1/map``...), and every frame
      seen there without the prefix is kept in :attr:`foreign_frames` (a crossed tree);
    - ``cmd_vel`` / ``cmd_vel_stamped``: the velocity commands (their simulated arrival times);
    - ``collisions`` (latched JSON from the playground);
    - ``easynav_manager_info``: the goals still to visit and the distance to the current one;
    - ``path_topic``: the planner's debug path (each new plan is kept, with the simulated time
      it arrived: :meth:`paths_record`);
    - ``easynav_heartbeat`` (when EasyNav publishes it): the late RT cycles since activation.

    Thread contract: callbacks run in the executor that spins this node (the demo's main
    thread); read the attributes from that thread, or under :attr:`lock`.
    """

    def __init__(
        self,
        path_topic: str | None,
        frames: dict[str, str] | None = None,
        frame_prefix: str = "",
        estimate_topic: str | None = None,
        **kwargs,
    ) -> None:
        super().__init__(
            "easynav_demo", parameter_overrides=[Parameter("use_sim_time", value=True)], **kwargs
        )
        self.frame_prefix = frame_prefix
        pre = f"{frame_prefix}/" if frame_prefix else ""
        self.frames = {
            "map": f"{pre}map", "odom": f"{pre}odom", "base": f"{pre}base_footprint",
            **(frames or {}),
        }
        self.foreign_frames: set[str] = set()
        self.lock = threading.Lock()
        self.estimates = GroundTruthRecorder()
        self.truth: tuple[float, float, float, float] | None = None  # stamp, x, y, yaw
        self.speed = 0.0
        self.map_to_odom: tuple[float, float, float] | None = None
        self.command_stamps: list[float] = []
        self.collision_count = 0
        self.collisions: list[dict] = []
        self.remaining_goals: int | None = None
        self.distance_to_goal: float | None = None
        self.paths: list[np.ndarray] = []
        self.path_times: list[float] = []  # simulated time each of ``paths`` arrived
        self.late_cycles: int | None = None
        reliable = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        latest = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
        self.create_subscription(Odometry, "ground_truth", self._on_truth, latest)
        self.create_subscription(
            TFMessage, "tf" if frame_prefix else "/tf", self._on_tf, reliable
        )
        self.create_subscription(Twist, "cmd_vel", self._on_cmd, reliable)
        self.create_subscription(TwistStamped, "cmd_vel_stamped", self._on_cmd, reliable)
        self.create_subscription(String, "collisions", self._on_collisions, latched)
        self.create_subscription(
            GoalManagerInfo, "easynav_manager_info", self._on_info, goal_topics_qos()
        )
        if path_topic:
            self.create_subscription(PathMsg, path_topic, self._on_path, 10)
        self._estimates_from_tf = estimate_topic is None
        if estimate_topic:
            self.create_subscription(Odometry, estimate_topic, self._on_estimate, reliable)
        self.create_subscription(Heartbeat, "easynav_heartbeat", self._on_heartbeat, 10)

    # ------------------------------------------------------------------ callbacks
    def _on_truth(self, msg: Odometry) -> None:
        p = msg.pose.pose
        with self.lock:
            self.truth = (
                time_from_msg(msg.header.stamp),
                p.position.x,
                p.position.y,
                _yaw(p.orientation),
            )
            self.speed = msg.twist.twist.linear.x

    def _on_estimate(self, msg: Odometry) -> None:
        p = msg.pose.pose
        with self.lock:
            self.estimates.record_estimate(
                time_from_msg(msg.header.stamp), p.position.x, p.position.y, _yaw(p.orientation)
            )

    def _on_heartbeat(self, msg: Heartbeat) -> None:
        with self.lock:
            self.late_cycles = max(self.late_cycles or 0, int(msg.late_cycles))

    def _on_tf(self, msg: TFMessage) -> None:
        f = self.frames
        for t in msg.transforms:
            parent, child = t.header.frame_id.lstrip("/"), t.child_frame_id.lstrip("/")
            if self.frame_prefix:
                foreign = {
                    frame for frame in (parent, child)
                    if not frame.startswith(f"{self.frame_prefix}/")
                }
                if foreign:
                    with self.lock:
                        self.foreign_frames |= foreign
            tr = t.transform
            pose = (tr.translation.x, tr.translation.y, _yaw(tr.rotation))
            if (parent, child) == (f["map"], f["odom"]):
                with self.lock:
                    self.map_to_odom = pose
            elif (parent, child) == (f["odom"], f["base"]) and self._estimates_from_tf:
                with self.lock:
                    if self.map_to_odom is not None:
                        x, y, yaw = compose(self.map_to_odom, pose)
                        self.estimates.record_estimate(time_from_msg(t.header.stamp), x, y, yaw)

    def _on_cmd(self, _msg) -> None:
        with self.lock:
            self.command_stamps.append(self.get_clock().now().nanoseconds * 1e-9)

    def _on_collisions(self, msg: String) -> None:
        try:
            data = json.loads(msg.data)
        except json.JSONDecodeError:
            self.get_logger().error(f"unreadable collisions message: {msg.data!r}")
            return
        with self.lock:
            self.collision_count = int(data.get("count", 0))
            if data.get("last"):
                self.collisions.append(data["last"])

    def _on_info(self, msg: GoalManagerInfo) -> None:
        with self.lock:
            if msg.status == GoalManagerInfo.ACTIVE:
                self.remaining_goals = len(msg.goals.goals)
                self.distance_to_goal = msg.position_distance

    def _on_path(self, msg: PathMsg) -> None:
        if not msg.poses:
            return
        points = np.array([(p.pose.position.x, p.pose.position.y) for p in msg.poses])
        with self.lock:
            if (
                self.paths
                and self.paths[-1].shape == points.shape
                and np.allclose(self.paths[-1], points)
            ):
                return
            self.paths.append(points)
            self.path_times.append(self.get_clock().now().nanoseconds * 1e-9)

    # ------------------------------------------------------------------ results
    def paths_record(self) -> list[dict]:
        """Each new plan as ``{"t": simulated seconds, "xy": [[x, y], ...]}`` (mm), in order:
        the run directory's ``paths.json``, to see which route the robot was given when."""
        with self.lock:
            return [
                {"t": round(t, 3), "xy": np.round(points, 3).tolist()}
                for t, points in zip(self.path_times, self.paths, strict=True)
            ]

    def command_rate(self, start: float, end: float) -> float:
        """Velocity commands per simulated second between two stamps (0 when none)."""
        with self.lock:
            stamps = [s for s in self.command_stamps if start <= s <= end]
        return len(stamps) / (end - start) if end > start and stamps else 0.0
