"""RobotPort: one simulated robot's ROS side (its topics, TF and frames) in the playground node."""

from __future__ import annotations

import json
import time

import numpy as np
from geometry_msgs.msg import Pose2D, Twist, TwistStamped
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Bool, String

from easynav.playground.ros import messages
from easynav.playground.sim import Collision, GnssReceiver, ImuSensor, Simulation, Terrain
from easynav.system.tf import StaticTFBroadcaster, TFBroadcaster

_RELIABLE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
_LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
#: The frames of a robot (playground parameters of the same names).
FRAME_KEYS = (
    "map_frame",
    "odom_frame",
    "robot_footprint_frame",
    "robot_frame",
    "laser_frame",
    "lidar_frame",
    "imu_frame",
    "gnss_frame",
)


def prefixed(prefix: str, name: str) -> str:
    """``name`` under ``prefix`` (``"r1"`` + ``"odom"`` → ``"r1/odom"``; no prefix: as is)."""
    return f"{prefix}/{name}" if prefix else name


class RobotPort:
    """The topics and transforms of one robot ``simulation`` on ``node``.

    With a ``name`` (several robots) every topic is relative under it (``r1/scan``,
    ``r1/odom``, ``r1/cmd_vel``, ``r1/tf``, ``r1/tf_static``, ``r1/playground/hold``...: the
    node lives in the root namespace, so they resolve to ``/r1/...``) and every frame is
    prefixed with it (``r1/odom``, ``r1/base_footprint``, ``r1/map`` for the ground truth),
    as EasyNav's ``system_node.tf_prefix: r1`` expects. Without a name (one robot) topics and
    frames are the playground's usual ones.

    Thread contract: built and :meth:`start` ed in the node's thread; the publishing methods
    run in the simulation loop thread; the subscription callbacks in the executor thread,
    where they only hand their value to the simulation (under its lock).
    """

    def __init__(
        self,
        node,
        name: str,
        simulation: Simulation,
        frames: dict[str, str],
        imu: ImuSensor | None = None,
        gnss: GnssReceiver | None = None,
        terrain: Terrain | None = None,
        base_link_height: float = 0.05,
        laser_z: float = 0.25,
        lidar_offset: tuple[float, float, float, float] = (0.0, 0.0, 0.45, 0.0),
    ) -> None:
        self.node = node
        self.name = name
        self.sim = simulation
        self.frames = {k: prefixed(name, frames[k]) for k in FRAME_KEYS}
        self.imu = imu
        self.gnss = gnss
        self.terrain = terrain
        self._base_link_height = float(base_link_height)
        self._laser_z = float(laser_z)
        self._lidar_offset = lidar_offset
        self.rejected_commands = 0
        self._warned_lateral = False

        def topic(relative: str) -> str:
            return prefixed(name, relative)

        self._scan_pub = node.create_publisher(messages.LaserScan, topic("scan"), _RELIABLE)
        self._cloud_pub = None
        if simulation.lidar is not None:
            from sensor_msgs.msg import PointCloud2

            self._cloud_pub = node.create_publisher(PointCloud2, topic("points"), _RELIABLE)
        self._odom_pub = node.create_publisher(messages.Odometry, topic("odom"), _RELIABLE)
        self._truth_pub = node.create_publisher(
            messages.Odometry, topic("ground_truth"), _RELIABLE
        )
        self._collisions_pub = node.create_publisher(String, topic("collisions"), _LATCHED)
        self._tf = TFBroadcaster(node, topic("tf"))
        self._tf_static = StaticTFBroadcaster(node, topic("tf_static"))
        node.create_subscription(Twist, topic("cmd_vel"), self.on_cmd_vel, _RELIABLE)
        node.create_subscription(
            TwistStamped, topic("cmd_vel_stamped"), self.on_cmd_vel_stamped, _RELIABLE
        )
        # Transient local, so that a latched hold published before this node started applies.
        node.create_subscription(Bool, topic("playground/hold"), self.on_hold, _LATCHED)
        node.create_subscription(Pose2D, topic("playground/teleport"), self.on_teleport, _RELIABLE)
        if imu is not None:
            self._imu_pub = node.create_publisher(messages.Imu, topic("imu/data"), _RELIABLE)
            simulation.add_periodic(imu.period, self.publish_imu)
        if gnss is not None:
            # The same fix on both names a GNSS consumer uses: robot_localization's (the fusion
            # and GTSAM localizers, through sensors_node) and the fixed topic of the original
            # GpsLocalizer, which is no parameter (without it that localizer never had a fix).
            self._gnss_pubs = [
                node.create_publisher(messages.NavSatFix, topic(name), _RELIABLE)
                for name in ("gps/fix", "robot/gps/fix")
            ]
            simulation.add_periodic(gnss.period, self.publish_gnss)
        simulation.on_scan.append(self.publish_scan)
        simulation.on_cloud.append(self.publish_cloud)
        simulation.on_odometry.append(self.publish_odometry)
        simulation.on_collision.append(self.publish_collision)

    @property
    def label(self) -> str:
        """How log lines name this robot (``"r1: "``; empty for a robot alone)."""
        return f"{self.name}: " if self.name else ""

    def start(self) -> None:
        """Publish the static transforms and the latched collision count."""
        f = self.frames
        sim = self.sim
        lidar_tf = []
        if sim.lidar is not None:
            ox, oy, oz, oyaw = self._lidar_offset
            lidar_tf.append(
                messages.planar_transform_msg(
                    0.0, f["robot_frame"], f["lidar_frame"], ox, oy,
                    oz - self._base_link_height, oyaw,
                )
            )
        self._tf_static.send_transform(
            lidar_tf + [
                messages.planar_transform_msg(
                    0.0,
                    f["robot_footprint_frame"],
                    f["robot_frame"],
                    0.0,
                    0.0,
                    self._base_link_height,
                ),
                messages.planar_transform_msg(
                    0.0,
                    f["robot_frame"],
                    f["laser_frame"],
                    sim.laser_offset[0],
                    sim.laser_offset[1],
                    self._laser_z - self._base_link_height,
                    sim.laser_offset[2],
                ),
            ]
            # The outdoor sensors sit on the base (only in worlds that have them).
            + [messages.planar_transform_msg(0.0, f["robot_frame"], f[frame], 0.0, 0.0)
               for frame, sensor in (("imu_frame", self.imu), ("gnss_frame", self.gnss))
               if sensor is not None]
        )
        self._collisions_pub.publish(String(data=json.dumps({"count": 0, "last": None})))

    def record(self, start_pose: tuple[float, float, float]) -> dict:
        """This robot's ground truth and statistics (the playground's record format)."""
        sim = self.sim
        data = sim.recorder.to_dict()
        data["sim_time"] = sim.time
        data["commands_received"] = sim.commands_received
        data["commands_rejected"] = self.rejected_commands
        data["start_pose"] = list(start_pose)
        data["holds"] = [list(event) for event in sim.hold_events]
        data["teleports"] = [list(event) for event in sim.teleport_events]
        data["commands"] = [list(event) for event in sim.command_events]
        data["obstacles"] = [
            {"name": o.name, "started_at": getattr(o, "started_at", 0.0)} for o in sim.obstacles
        ]
        return data

    # ------------------------------------------------------------------ simulation thread
    def publish_scan(self, stamp: float, ranges: np.ndarray) -> None:
        self._scan_pub.publish(
            messages.laser_scan_msg(self.sim.scanner, ranges, stamp, self.frames["laser_frame"])
        )

    def publish_cloud(self, stamp: float, points: np.ndarray) -> None:
        from easynav.system.sensors.converters.point_cloud2 import point_cloud2_from_points

        self._cloud_pub.publish(point_cloud2_from_points(points, self.frames["lidar_frame"], stamp))

    def publish_odometry(self, stamp: float) -> None:
        f = self.frames
        odom = self.sim.odometry
        self._odom_pub.publish(
            messages.planar_odometry_msg(
                stamp,
                f["odom_frame"],
                f["robot_footprint_frame"],
                (odom.x, odom.y, odom.yaw),
                (odom.v, odom.w),
                pose_variance=(0.01, 0.01),
            )
        )
        self._tf.send_transform(
            messages.planar_transform_msg(
                stamp, f["odom_frame"], f["robot_footprint_frame"], odom.x, odom.y, 0.0, odom.yaw
            )
        )
        robot = self.sim.robot
        truth = messages.planar_odometry_msg(
            stamp,
            f["map_frame"],
            f["robot_footprint_frame"],
            (robot.x, robot.y, robot.yaw),
            (robot.v, robot.w),
        )
        if self.terrain is not None:
            truth.pose.pose.position.z = self.terrain.height(robot.x, robot.y)
        elif self.sim.levels is not None:
            truth.pose.pose.position.z = self.sim.z
        self._truth_pub.publish(truth)

    def publish_imu(self, stamp: float) -> None:
        robot = self.sim.robot
        reading = self.imu.sample(stamp, robot.yaw, robot.v, robot.w)
        self._imu_pub.publish(messages.imu_msg(reading, self.frames["imu_frame"]))

    def publish_gnss(self, stamp: float) -> None:
        robot = self.sim.robot
        msg = messages.nav_sat_fix_msg(self.gnss.fix(stamp, robot.x, robot.y),
                                       self.frames["gnss_frame"])
        for publisher in self._gnss_pubs:
            publisher.publish(msg)

    def publish_collision(self, collision: Collision) -> None:
        count = len(self.sim.checker.collisions)
        self.node.get_logger().warning(
            f"{self.label}collision #{count} with {collision.with_what} at ({collision.x:.2f}, "
            f"{collision.y:.2f}), t={collision.stamp:.2f} s"
        )
        self._collisions_pub.publish(
            String(data=json.dumps({"count": count, "last": collision.as_dict()}))
        )

    # ------------------------------------------------------------------ executor thread
    def on_hold(self, msg: Bool) -> None:
        if bool(msg.data) != self.sim.held:
            self.sim.set_held(msg.data)
            self.node.get_logger().warning(
                f"{self.label}robot "
                f"{'held in place (wheels blocked)' if msg.data else 'released'} at "
                f"t={self.sim.time:.2f} s"
            )

    def on_teleport(self, msg: Pose2D) -> None:
        try:
            self.sim.teleport(msg.x, msg.y, msg.theta)
        except ValueError as exc:
            self.node.get_logger().warning(f"{self.label}playground/teleport refused: {exc}")
            return
        self.node.get_logger().warning(
            f"{self.label}teleport to ({msg.x:.2f}, {msg.y:.2f}, {msg.theta:.2f}) at "
            f"t={self.sim.time:.2f} s (no odometry of the move; refused at the next step if in "
            "collision)"
        )

    def on_cmd_vel(self, msg: Twist) -> None:
        self.command(msg)

    def on_cmd_vel_stamped(self, msg: TwistStamped) -> None:
        self.command(msg.twist)

    def command(self, twist: Twist) -> None:
        lin, ang = twist.linear, twist.angular
        if not self._warned_lateral and (lin.y or lin.z or ang.x or ang.y):
            self._warned_lateral = True
            self.node.get_logger().warning(
                f"{self.label}cmd_vel with linear.y={lin.y}, linear.z={lin.z}, "
                f"angular.x={ang.x}, angular.y={ang.y}: a differential drive only executes "
                "linear.x and angular.z (warned once)"
            )
        try:
            self.sim.set_command(lin.x, ang.z, time.time())
        except ValueError as err:
            # A driver must not keep moving on garbage: stop and say why.
            self.rejected_commands += 1
            self.sim.set_command(0.0, 0.0)
            self.node.get_logger().error(f"{self.label}rejected cmd_vel, stopping the base: {err}")
