"""PlaygroundNode: the simulated robot as a ROS 2 node (a driver, a laser and /clock)."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
from geometry_msgs.msg import Pose2D, Twist, TwistStamped
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Bool, String

from easynav.core.tf import StaticTFBroadcaster, TFBroadcaster
from easynav.playground.fixed_rate_loop import FixedRateLoop
from easynav.playground.ros import messages
from easynav.playground.sim import (
    BaseLimits,
    Collision,
    DiffDriveRobot,
    GnssReceiver,
    ImuSensor,
    LaserScanner,
    Lidar3D,
    Simulation,
    Terrain,
    WheelOdometry,
)
from easynav.playground.world_description import WorldDescription

#: Parameters of the node and their defaults (see the README's parameter table).
DEFAULT_PARAMETERS: dict[str, object] = {
    "world": "home",
    "speed_up": 1.0,
    "seed": 0,
    "step": 0.005,
    "start_pose": [math.nan, math.nan, math.nan],
    "robot_radius": 0.2,
    "robot_height": 0.5,
    "cmd_timeout": 0.0,
    "odom_rate": 50.0,
    "moving_obstacles": True,
    "hold": False,
    "record": "",
    "map_frame": "map",
    "odom_frame": "odom",
    "robot_footprint_frame": "base_footprint",
    "robot_frame": "base_link",
    "laser_frame": "base_laser",
    "lidar_frame": "base_lidar",
    "base_link_height": 0.05,
    "laser.beams": 360,
    "laser.fov": 2.0 * math.pi,
    "laser.min_range": 0.12,
    "laser.max_range": 10.0,
    "laser.rate": 10.0,
    "laser.noise_std": 0.01,
    "laser.x": 0.1,
    "laser.y": 0.0,
    "laser.z": 0.25,
    "laser.yaw": 0.0,
    "lidar.enabled": False,
    "lidar.rings": 16,
    "lidar.beams": 180,
    "lidar.min_elevation": -0.26,
    "lidar.max_elevation": 0.26,
    "lidar.min_range": 0.2,
    "lidar.max_range": 8.0,
    "lidar.rate": 5.0,
    "lidar.noise_std": 0.01,
    "lidar.x": 0.0,
    "lidar.y": 0.0,
    "lidar.z": 0.45,
    "lidar.yaw": 0.0,
    "odometry.linear_scale": 1.01,
    "odometry.angular_scale": 0.99,
    "odometry.linear_noise": 0.01,
    "odometry.angular_noise": 0.02,
    "odometry.drift_per_metre": 0.01,
    "base.max_linear_vel": 0.7,
    "base.max_angular_vel": 3.0,
    "base.max_linear_acc": 1.5,
    "base.max_linear_decel": 3.0,
    "base.max_angular_acc": 6.0,
    "base.max_angular_decel": 8.0,
    # Outdoor sensors (on in worlds that declare them: see WorldDescription).
    "geodetic_origin": [math.nan, math.nan, math.nan],
    "imu_frame": "imu_link",
    "gnss_frame": "gps_link",
    "imu.enabled": False,
    "imu.rate": 50.0,
    "imu.gyro_noise": 0.005,
    "imu.gyro_bias": 0.002,
    "imu.accel_noise": 0.05,
    "imu.yaw_noise": 0.02,
    "gnss.enabled": False,
    "gnss.rate": 5.0,
    "gnss.noise": 0.3,
    "gnss.jump_probability": 0.0,
    "gnss.jump_distance": 30.0,
    "gnss.outages": [0.0, 0.0],
    # Worlds with terrain (heights): the steepest ground the robot climbs (the world's value).
    "terrain.max_climb_slope_deg": 30.0,
}

_RELIABLE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
_LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


class PlaygroundNode(Node):
    """The playground robot: runs a :class:`Simulation` in simulated time and talks ROS.

    Publishes ``/clock`` (every step), ``scan`` (``laser.rate``), ``points`` (the 3D lidar's
    PointCloud2 in ``lidar_frame``, ``lidar.rate``, with ``lidar.enabled``), ``odom`` and the
    ``odom -> base_footprint`` transform on ``tf`` (``odom_rate``), ``ground_truth`` (true pose
    in the map frame, same rate; its z is the ground height on a world with terrain), the
    static ``base_footprint -> base_link -> base_laser`` (and ``-> base_lidar``) transforms on
    ``tf_static``, ``collisions`` (latched JSON: count and the last collision) and the world on
    ``playground/world`` (latched OccupancyGrid). Subscribes ``cmd_vel`` (Twist),
    ``cmd_vel_stamped`` (TwistStamped) and ``playground/hold`` (std_msgs/Bool, transient local:
    hold the robot in place, wheels blocked; the ``hold`` parameter is the initial state) and
    ``playground/teleport`` (geometry_msgs/Pose2D in the map frame: the robot is carried there,
    stopped, with no odometry of the move: a kidnapped robot; a pose in collision is refused
    with a warning). It publishes /clock; it does not use it.

    Thread contract: construct, :meth:`start` and :meth:`stop` from the main thread. Command
    callbacks run in the executor thread and only hand the command to the simulation (under
    its lock); the simulation loop thread steps and publishes.

    Raises:
        ValueError: a bad parameter (names it), or a start pose in collision.
        FileNotFoundError: an unknown world.
    """

    def __init__(self, **kwargs) -> None:
        super().__init__("playground", **kwargs)
        if not self.has_parameter("world"):
            self.declare_parameter("world", DEFAULT_PARAMETERS["world"])
        p = self._param
        self.description = WorldDescription.resolve(str(p("world")))
        # The world's robot (radius, base limits, laser) replaces the defaults; a parameter
        # given explicitly (an override) still wins over both.
        defaults = {
            **DEFAULT_PARAMETERS,
            **self.description.robot.parameter_defaults(),
            **self.description.sensor_parameter_defaults(),
            "terrain.max_climb_slope_deg": self.description.max_climb_slope_deg,
        }
        for name, default in defaults.items():
            if not self.has_parameter(name):
                self.declare_parameter(name, default)
        speed_up = float(p("speed_up"))
        if not (math.isfinite(speed_up) and speed_up > 0.0):
            raise ValueError(f"playground: speed_up must be finite and > 0, got {speed_up}")
        self.speed_up = speed_up
        seed = int(p("seed"))
        start = [float(v) for v in p("start_pose")]
        if len(start) != 3:
            raise ValueError(f"playground: start_pose must be [x, y, yaw], got {start}")
        if any(math.isnan(v) for v in start):
            start = list(self.description.start_pose)
        self.start_pose = tuple(start)
        # Children by index: adding sensors at the end leaves the earlier streams unchanged.
        rng_scan, rng_odom, rng_lidar, rng_imu, rng_gnss = (
            np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(5)
        )
        limits = BaseLimits(**{k: float(p(f"base.{k}")) for k in BaseLimits.__slots__})
        robot = DiffDriveRobot(*self.start_pose, limits=limits, cmd_timeout=float(p("cmd_timeout")))
        self.scanner = LaserScanner(
            beams=int(p("laser.beams")),
            fov=float(p("laser.fov")),
            min_range=float(p("laser.min_range")),
            max_range=float(p("laser.max_range")),
            rate=float(p("laser.rate")),
            range_noise_std=float(p("laser.noise_std")),
            rng=rng_scan,
        )
        odometry = WheelOdometry(
            linear_scale=float(p("odometry.linear_scale")),
            angular_scale=float(p("odometry.angular_scale")),
            linear_noise=float(p("odometry.linear_noise")),
            angular_noise=float(p("odometry.angular_noise")),
            drift_per_metre=float(p("odometry.drift_per_metre")),
            rng=rng_odom,
        )
        obstacles = self.description.make_obstacles() if p("moving_obstacles") else []
        self.lidar = None
        if bool(p("lidar.enabled")):
            self.lidar = Lidar3D(
                rings=int(p("lidar.rings")),
                beams=int(p("lidar.beams")),
                min_elevation=float(p("lidar.min_elevation")),
                max_elevation=float(p("lidar.max_elevation")),
                min_range=float(p("lidar.min_range")),
                max_range=float(p("lidar.max_range")),
                rate=float(p("lidar.rate")),
                noise_std=float(p("lidar.noise_std")),
                rng=rng_lidar,
            )
        self._lidar_offset = tuple(float(p(f"lidar.{k}")) for k in ("x", "y", "z", "yaw"))
        self.terrain = None
        if self.description.terrain_path is not None:
            self.terrain = Terrain.load(
                self.description.terrain_path, float(p("terrain.max_climb_slope_deg"))
            )
        self.sim = Simulation(
            self.description.world,
            robot,
            self.scanner,
            odometry,
            obstacles=obstacles,
            robot_radius=float(p("robot_radius")),
            step=float(p("step")),
            odom_rate=float(p("odom_rate")),
            laser_offset=(float(p("laser.x")), float(p("laser.y")), float(p("laser.yaw"))),
            boxes=self.description.furniture,
            robot_height=float(p("robot_height")),
            laser_height=float(p("laser.z")),
            lidar=self.lidar,
            lidar_offset=self._lidar_offset,
            terrain=self.terrain,
        )
        self.record_path = str(p("record"))
        self.frames = {
            k: str(p(k))
            for k in (
                "map_frame",
                "odom_frame",
                "robot_footprint_frame",
                "robot_frame",
                "laser_frame",
                "lidar_frame",
            )
        }
        self.sim.set_held(bool(p("hold")))
        self._base_link_height = float(p("base_link_height"))
        self._laser_z = float(p("laser.z"))

        self._clock_pub = self.create_publisher(Clock, "/clock", _RELIABLE)
        self._scan_pub = self.create_publisher(messages.LaserScan, "scan", _RELIABLE)
        self._cloud_pub = None
        if self.lidar is not None:
            from sensor_msgs.msg import PointCloud2

            self._cloud_pub = self.create_publisher(PointCloud2, "points", _RELIABLE)
        self._odom_pub = self.create_publisher(messages.Odometry, "odom", _RELIABLE)
        self._truth_pub = self.create_publisher(messages.Odometry, "ground_truth", _RELIABLE)
        self._collisions_pub = self.create_publisher(String, "collisions", _LATCHED)
        self._world_pub = self.create_publisher(
            messages.OccupancyGrid, "playground/world", _LATCHED
        )
        self._tf = TFBroadcaster(self)
        self._tf_static = StaticTFBroadcaster(self)
        self.create_subscription(Twist, "cmd_vel", self._on_cmd_vel, _RELIABLE)
        self.create_subscription(
            TwistStamped, "cmd_vel_stamped", self._on_cmd_vel_stamped, _RELIABLE
        )
        # Transient local, so that a latched hold published before this node started applies.
        self.create_subscription(Bool, "playground/hold", self._on_hold, _LATCHED)
        self.create_subscription(Pose2D, "playground/teleport", self._on_teleport, _RELIABLE)
        self._warned_lateral = False
        self._rejected_commands = 0

        self.imu = None
        self.gnss = None
        if p("imu.enabled"):
            self.imu = ImuSensor(
                rate=float(p("imu.rate")), gyro_noise=float(p("imu.gyro_noise")),
                gyro_bias=float(p("imu.gyro_bias")), accel_noise=float(p("imu.accel_noise")),
                yaw_noise=float(p("imu.yaw_noise")), rng=rng_imu)
            self._imu_pub = self.create_publisher(messages.Imu, "imu/data", _RELIABLE)
            self.sim.add_periodic(self.imu.period, self._publish_imu)
        if p("gnss.enabled"):
            origin = [float(v) for v in p("geodetic_origin")]
            if len(origin) != 3 or not all(math.isfinite(v) for v in origin):
                raise ValueError(f"playground: gnss needs geodetic_origin [lat, lon, alt], got "
                                 f"{origin}")
            flat = [float(v) for v in p("gnss.outages")]
            if len(flat) % 2:
                raise ValueError(f"playground: gnss.outages must be [start, end, ...] pairs, "
                                 f"got {flat}")
            self.gnss = GnssReceiver(
                origin, rate=float(p("gnss.rate")), noise=float(p("gnss.noise")),
                jump_probability=float(p("gnss.jump_probability")),
                jump_distance=float(p("gnss.jump_distance")),
                outages=[flat[i:i + 2] for i in range(0, len(flat), 2)], rng=rng_gnss)
            self._gnss_pub = self.create_publisher(messages.NavSatFix, "gps/fix", _RELIABLE)
            self.sim.add_periodic(self.gnss.period, self._publish_gnss)
        self.frames["imu_frame"] = str(p("imu_frame"))
        self.frames["gnss_frame"] = str(p("gnss_frame"))

        self.sim.on_scan.append(self._publish_scan)
        self.sim.on_cloud.append(self._publish_cloud)
        self.sim.on_odometry.append(self._publish_odometry)
        self.sim.on_collision.append(self._publish_collision)
        self._loop = FixedRateLoop(
            self.sim.step_size / self.speed_up, self._tick, max_lag=0.25, name="playground-sim"
        )

    def _param(self, name: str):
        return self.get_parameter(name).value

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        """Publish the latched and static data, then start the simulation loop thread."""
        f = self.frames
        lidar_tf = []
        if self.lidar is not None:
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
                    self.sim.laser_offset[0],
                    self.sim.laser_offset[1],
                    self._laser_z - self._base_link_height,
                    self.sim.laser_offset[2],
                ),
            ]
            # The outdoor sensors sit on the base (only in worlds that have them).
            + [messages.planar_transform_msg(0.0, f["robot_frame"], f[frame], 0.0, 0.0)
               for frame, sensor in (("imu_frame", self.imu), ("gnss_frame", self.gnss))
               if sensor is not None]
        )
        self._world_pub.publish(
            messages.occupancy_grid_msg(self.description.world, 0.0, f["map_frame"])
        )
        self._collisions_pub.publish(String(data=json.dumps({"count": 0, "last": None})))
        x, y, yaw = self.start_pose
        self.get_logger().info(
            f"world '{self.description.world.name}' ({self.description.source or 'built in'}), "
            f"start ({x:.2f}, {y:.2f}, {yaw:.2f}), step {self.sim.step_size * 1000:.1f} ms, "
            f"speed-up x{self.speed_up:g}, {len(self.sim.obstacles)} moving obstacle(s)"
            + (f", terrain {self.description.terrain_path.name} (climbs up to "
               f"{self.terrain.max_climb_slope_deg:g} deg)" if self.terrain is not None else "")
        )
        self._loop.start()

    def stop(self) -> None:
        """Stop the simulation loop and write the record file when one was asked for.

        Raises:
            BaseException: what stopped the simulation loop, if it failed.
        """
        try:
            self._loop.stop()
        finally:
            if self.record_path:
                self.write_record(self.record_path)

    def write_record(self, path: str | Path) -> None:
        """Save the ground truth (trajectory, clearances, collisions) and run statistics."""
        rec = self.sim.recorder
        data = rec.to_dict()
        data["sim_time"] = self.sim.time
        data["wall_time"] = self._loop.elapsed()
        data["commands_received"] = self.sim.commands_received
        data["commands_rejected"] = self._rejected_commands
        data["start_pose"] = list(self.start_pose)
        data["holds"] = [list(event) for event in self.sim.hold_events]
        data["teleports"] = [list(event) for event in self.sim.teleport_events]
        data["commands"] = [list(event) for event in self.sim.command_events]
        data["obstacles"] = [
            {"name": o.name, "started_at": getattr(o, "started_at", 0.0)}
            for o in self.sim.obstacles
        ]
        data["world"] = self.description.world.name
        tmp = Path(path).with_name(Path(path).name + ".tmp")
        tmp.write_text(json.dumps(data))
        tmp.replace(path)

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall second achieved so far."""
        wall = self._loop.elapsed()
        return self.sim.time / wall if wall > 0 else 0.0

    @property
    def loop_running(self) -> bool:
        """False once the simulation loop stopped (after :meth:`stop` or on an error)."""
        return self._loop.running

    # ------------------------------------------------------------------ simulation thread
    def _tick(self) -> None:
        # /clock first: the messages of this step are stamped with its end time, and a
        # subscriber must never receive data stamped ahead of its clock.
        clock = Clock()
        clock.clock = messages.stamp_msg((self.sim.steps + 1) * self.sim.step_size)
        self._clock_pub.publish(clock)
        self.sim.step()

    def _publish_scan(self, stamp: float, ranges: np.ndarray) -> None:
        self._scan_pub.publish(
            messages.laser_scan_msg(self.scanner, ranges, stamp, self.frames["laser_frame"])
        )

    def _publish_cloud(self, stamp: float, points: np.ndarray) -> None:
        from easynav.core.sensors.converters.point_cloud2 import point_cloud2_from_points

        self._cloud_pub.publish(
            point_cloud2_from_points(points, self.frames["lidar_frame"], stamp)
        )

    def _publish_odometry(self, stamp: float) -> None:
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
        self._truth_pub.publish(truth)

    def _publish_imu(self, stamp: float) -> None:
        robot = self.sim.robot
        reading = self.imu.sample(stamp, robot.yaw, robot.v, robot.w)
        self._imu_pub.publish(messages.imu_msg(reading, self.frames["imu_frame"]))

    def _publish_gnss(self, stamp: float) -> None:
        robot = self.sim.robot
        fix = self.gnss.fix(stamp, robot.x, robot.y)
        self._gnss_pub.publish(messages.nav_sat_fix_msg(fix, self.frames["gnss_frame"]))

    def _publish_collision(self, collision: Collision) -> None:
        count = len(self.sim.checker.collisions)
        self.get_logger().warning(
            f"collision #{count} with {collision.with_what} at ({collision.x:.2f}, "
            f"{collision.y:.2f}), t={collision.stamp:.2f} s"
        )
        self._collisions_pub.publish(
            String(data=json.dumps({"count": count, "last": collision.as_dict()}))
        )

    # ------------------------------------------------------------------ executor thread
    def _on_hold(self, msg: Bool) -> None:
        if bool(msg.data) != self.sim.held:
            self.sim.set_held(msg.data)
            self.get_logger().warning(
                f"robot {'held in place (wheels blocked)' if msg.data else 'released'} at "
                f"t={self.sim.time:.2f} s"
            )

    def _on_teleport(self, msg: Pose2D) -> None:
        try:
            self.sim.teleport(msg.x, msg.y, msg.theta)
        except ValueError as exc:
            self.get_logger().warning(f"playground/teleport refused: {exc}")
            return
        self.get_logger().warning(
            f"teleport to ({msg.x:.2f}, {msg.y:.2f}, {msg.theta:.2f}) at t={self.sim.time:.2f} s "
            "(no odometry of the move; refused at the next step if in collision)"
        )

    def _on_cmd_vel(self, msg: Twist) -> None:
        self._command(msg)

    def _on_cmd_vel_stamped(self, msg: TwistStamped) -> None:
        self._command(msg.twist)

    def _command(self, twist: Twist) -> None:
        lin, ang = twist.linear, twist.angular
        if not self._warned_lateral and (lin.y or lin.z or ang.x or ang.y):
            self._warned_lateral = True
            self.get_logger().warning(
                f"cmd_vel with linear.y={lin.y}, linear.z={lin.z}, angular.x={ang.x}, "
                f"angular.y={ang.y}: a differential drive only executes linear.x and angular.z"
                " (warned once)"
            )
        try:
            self.sim.set_command(lin.x, ang.z, time.time())
        except ValueError as err:
            # A driver must not keep moving on garbage: stop and say why.
            self._rejected_commands += 1
            self.sim.set_command(0.0, 0.0)
            self.get_logger().error(f"rejected cmd_vel, stopping the base: {err}")


def parameter_overrides(values: dict[str, object]) -> list[Parameter]:
    """rclpy Parameters for :class:`PlaygroundNode` from plain values (CLI options).

    Raises:
        KeyError: a name that is not a playground parameter.
    """
    result = []
    for name, value in values.items():
        if name not in DEFAULT_PARAMETERS:
            raise KeyError(f"unknown playground parameter {name!r}")
        default = DEFAULT_PARAMETERS[name]
        if isinstance(default, float) and isinstance(value, int):
            value = float(value)
        if isinstance(default, list):
            value = [float(v) for v in value]
        result.append(Parameter(name, value=value))
    return result
