"""PlaygroundNode: the simulated robot as a ROS 2 node (a driver, a laser and /clock)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock

from easynav.playground.fixed_rate_loop import FixedRateLoop
from easynav.playground.ros import messages
from easynav.playground.ros.robot_port import FRAME_KEYS, RobotPort
from easynav.playground.sim import (
    BaseLimits,
    DiffDriveRobot,
    Fleet,
    GnssReceiver,
    ImuSensor,
    LaserScanner,
    Lidar3D,
    Simulation,
    Terrain,
    WheelOdometry,
)
from easynav.playground.world_description import WorldDescription

#: Simulated seconds the loop may run late and still catch up by stepping without sleeping.
#: Behind by more (the machine is loaded), it restarts its schedule: the world slows down with
#: the machine. A catch-up burst is the world jumping ahead while the navigation stack, on the
#: same CPUs, cannot look: 0.5 s compressed into 80 ms of wall time walked a person into a
#: braking robot that had no scan of them yet. 50 ms is a cycle and a half of a 30 Hz RT loop;
#: beside three busy processes at x2 it kept x1.6-1.8 of the speed (20 ms: x1.4-1.55, with a
#: restart every 0.15 s; 0.25 s of wall time, as before: x1.7-1.8).
MAX_CATCH_UP = 0.05

#: Parameters of the node and their defaults (see the README's parameter table).
DEFAULT_PARAMETERS: dict[str, object] = {
    "world": "home",
    "speed_up": 1.0,
    "seed": 0,
    "robots": 1,
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

    With ``robots`` N > 1 the world's first N ``robots`` (:class:`WorldDescription`) share the
    world in a :class:`Fleet` (each laser sees the others, collisions between them are
    recorded): each robot's topics above are under its name (``r1/scan``, ``r1/odom``,
    ``r1/cmd_vel``, ``r1/tf``, ``r1/tf_static``, ``r1/playground/hold``...) and its frames are
    prefixed with it (``r1/odom``, ``r1/base_footprint``, ``r1/map``...: a
    :class:`RobotPort` each); ``/clock`` and ``playground/world`` are shared, and the record
    holds each robot's ground truth under ``robots``. ``start_pose`` is for one robot only.

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
        count = int(p("robots"))
        if count < 1:
            raise ValueError(f"playground: robots must be >= 1, got {count}")
        start = [float(v) for v in p("start_pose")]
        if len(start) != 3:
            raise ValueError(f"playground: start_pose must be [x, y, yaw], got {start}")
        if count == 1:
            if any(math.isnan(v) for v in start):
                start = list(self.description.start_pose)
            robots = [("", tuple(start))]
        else:
            if not all(math.isnan(v) for v in start):
                raise ValueError(
                    "playground: start_pose is for one robot; with robots > 1 the start poses "
                    "are the world's ('robots' of its description)"
                )
            robots = [(e.name, e.start_pose) for e in self.description.fleet(count)]
        self.start_pose = robots[0][1]
        self.start_poses = [pose for _name, pose in robots]
        self.robot_names = [name for name, _pose in robots]
        # Five noise streams per robot, children by index: adding sensors at the end leaves
        # the earlier streams unchanged, and the first robot's are those of a robot alone.
        streams = np.random.SeedSequence(seed).spawn(5 * count)
        rngs = [np.random.default_rng(s) for s in streams]
        self._lidar_offset = tuple(float(p(f"lidar.{k}")) for k in ("x", "y", "z", "yaw"))
        self.terrain = None
        if self.description.terrain_path is not None:
            self.terrain = Terrain.load(
                self.description.terrain_path, float(p("terrain.max_climb_slope_deg"))
            )
        # Multi-level worlds: floors and ramps (what each level hits and sees depends on the
        # robot's height and its laser's).
        self.levels = self.description.make_levels(float(p("robot_height")), float(p("laser.z")))
        obstacles = self.description.make_obstacles() if p("moving_obstacles") else []
        simulations = [
            self._make_simulation(pose, rngs[5 * i:5 * i + 5], obstacles if count == 1 else [])
            for i, (_name, pose) in enumerate(robots)
        ]
        #: What the loop steps: the robot's Simulation, or the Fleet of several.
        self.fleet = None
        self._stepper = simulations[0]
        if count > 1:
            self.fleet = Fleet(simulations, self.robot_names, obstacles=obstacles)
            self._stepper = self.fleet
        self.sim = simulations[0]
        self.scanner = self.sim.scanner
        self.lidar = self.sim.lidar
        self.record_path = str(p("record"))
        frames = {k: str(p(k)) for k in FRAME_KEYS}
        for sim in simulations:
            sim.set_held(bool(p("hold")))
        self._clock_pub = self.create_publisher(Clock, "/clock", _RELIABLE)
        self._world_pub = self.create_publisher(
            messages.OccupancyGrid, "playground/world", _LATCHED
        )
        self.ports = [
            RobotPort(
                self, name, sim, frames,
                imu=self._make_imu(rngs[5 * i + 3]),
                gnss=self._make_gnss(rngs[5 * i + 4]),
                terrain=self.terrain,
                base_link_height=float(p("base_link_height")),
                laser_z=float(p("laser.z")),
                lidar_offset=self._lidar_offset,
            )
            for i, (name, sim) in enumerate(zip(self.robot_names, simulations, strict=True))
        ]
        self.frames = self.ports[0].frames
        self.imu = self.ports[0].imu
        self.gnss = self.ports[0].gnss
        self._loop = FixedRateLoop(
            self.sim.step_size / self.speed_up, self._tick,
            max_lag=MAX_CATCH_UP / self.speed_up, name="playground-sim",
        )

    def _param(self, name: str):
        return self.get_parameter(name).value

    def _make_simulation(self, start_pose, rngs, obstacles) -> Simulation:
        """One robot at ``start_pose`` with noise streams ``rngs`` (scan, odometry, lidar,
        IMU, GNSS)."""
        p = self._param
        rng_scan, rng_odom, rng_lidar = rngs[:3]
        limits = BaseLimits(**{k: float(p(f"base.{k}")) for k in BaseLimits.__slots__})
        robot = DiffDriveRobot(*start_pose, limits=limits, cmd_timeout=float(p("cmd_timeout")))
        scanner = LaserScanner(
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
        lidar = None
        if bool(p("lidar.enabled")):
            lidar = Lidar3D(
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
        return Simulation(
            self.description.world,
            robot,
            scanner,
            odometry,
            obstacles=obstacles,
            robot_radius=float(p("robot_radius")),
            step=float(p("step")),
            odom_rate=float(p("odom_rate")),
            laser_offset=(float(p("laser.x")), float(p("laser.y")), float(p("laser.yaw"))),
            boxes=self.description.furniture,
            robot_height=float(p("robot_height")),
            laser_height=float(p("laser.z")),
            lidar=lidar,
            lidar_offset=self._lidar_offset,
            terrain=self.terrain,
            levels=self.levels,
        )

    def _make_imu(self, rng) -> ImuSensor | None:
        p = self._param
        if not p("imu.enabled"):
            return None
        return ImuSensor(
            rate=float(p("imu.rate")), gyro_noise=float(p("imu.gyro_noise")),
            gyro_bias=float(p("imu.gyro_bias")), accel_noise=float(p("imu.accel_noise")),
            yaw_noise=float(p("imu.yaw_noise")), rng=rng)

    def _make_gnss(self, rng) -> GnssReceiver | None:
        p = self._param
        if not p("gnss.enabled"):
            return None
        origin = [float(v) for v in p("geodetic_origin")]
        if len(origin) != 3 or not all(math.isfinite(v) for v in origin):
            raise ValueError(f"playground: gnss needs geodetic_origin [lat, lon, alt], got "
                             f"{origin}")
        flat = [float(v) for v in p("gnss.outages")]
        if len(flat) % 2:
            raise ValueError(f"playground: gnss.outages must be [start, end, ...] pairs, "
                             f"got {flat}")
        return GnssReceiver(
            origin, rate=float(p("gnss.rate")), noise=float(p("gnss.noise")),
            jump_probability=float(p("gnss.jump_probability")),
            jump_distance=float(p("gnss.jump_distance")),
            outages=[flat[i:i + 2] for i in range(0, len(flat), 2)], rng=rng)

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        """Publish the latched and static data, then start the simulation loop thread."""
        for port in self.ports:
            port.start()
        self._world_pub.publish(
            messages.occupancy_grid_msg(self.description.world, 0.0, self.frames["map_frame"])
        )
        x, y, yaw = self.start_pose
        where = (
            f"start ({x:.2f}, {y:.2f}, {yaw:.2f})"
            if self.fleet is None
            else f"{len(self.ports)} robots: " + ", ".join(
                f"{name} at ({pose[0]:.2f}, {pose[1]:.2f}, {pose[2]:.2f})"
                for name, pose in zip(self.robot_names, self.start_poses, strict=True)
            )
        )
        self.get_logger().info(
            f"world '{self.description.world.name}' ({self.description.source or 'built in'}), "
            f"{where}, step {self.sim.step_size * 1000:.1f} ms, "
            f"speed-up x{self.speed_up:g}, {len(self.sim.obstacles)} moving obstacle(s)"
            + (f", terrain {self.description.terrain_path.name} (climbs up to "
               f"{self.terrain.max_climb_slope_deg:g} deg)" if self.terrain is not None else "")
            + (f", levels {', '.join(self.levels.level_names)} (on {self.sim.level})"
               if self.levels is not None else "")
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
        """Save the ground truth (trajectory, clearances, collisions) and run statistics.

        One robot: its record at the top level. Several: ``robots`` maps each name to its
        record (the same keys), beside ``sim_time``, ``wall_time`` and ``world``.
        """
        if self.fleet is None:
            data = self.ports[0].record(self.start_pose)
        else:
            data = {
                "robots": {
                    port.name: port.record(pose)
                    for port, pose in zip(self.ports, self.start_poses, strict=True)
                },
                "sim_time": self.sim.time,
            }
        data["wall_time"] = self._loop.elapsed()
        data["schedule_restarts"] = self.schedule_restarts
        data["world"] = self.description.world.name
        tmp = Path(path).with_name(Path(path).name + ".tmp")
        tmp.write_text(json.dumps(data))
        tmp.replace(path)

    @property
    def collision_count(self) -> int:
        """Collisions of every robot so far."""
        return sum(len(port.sim.checker.collisions) for port in self.ports)

    @property
    def schedule_restarts(self) -> int:
        """Times the simulation fell more than :data:`MAX_CATCH_UP` behind its schedule and
        went on from where it was (the machine could not keep up)."""
        return self._loop.restarts

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
        self._stepper.step()

    # ------------------------------------------------------------------ executor thread
    def _on_cmd_vel(self, msg: Twist) -> None:
        """The first robot's ``cmd_vel`` callback (tests call it directly)."""
        self.ports[0].on_cmd_vel(msg)

    @property
    def _rejected_commands(self) -> int:
        return self.ports[0].rejected_commands


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
