"""AMCLLocalizer (easynav_simple_localizer/AMCLLocalizer): a particle filter on the simple map."""

from __future__ import annotations

import math
import threading

import numpy as np

from easynav.common.sensors import PointPerception, PointPerceptionsOps
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import MAP_BASE, ROBOT_POSE, NavStateKey
from easynav.core.plugins import LocalizerMethodBase, Param, Topic
from easynav.core.types import (
    Header,
    Odometry,
    Pose,
    Transform,
    TransformStamped,
    Twist,
    normalize_angle,
    yaw_to_quaternion,
)
from easynav.core.warning_throttle import WarningThrottle
from easynav.localizers.particle_filter import (
    ParticleFilter2D,
    compiled_scoring_pays,
    hit_fractions,
    likelihood_field,
)
from easynav.maps import SimpleMap

#: NavState keys.
MAP_KEY = MAP_BASE
POSE_KEY = ROBOT_POSE
COVARIANCE_TRACE_KEY = NavStateKey(
    "localizer.amcl.covariance_trace", "float", "var x + var y + var yaw of the particle cloud."
)
#: Points at or below this height in the robot footprint frame are ground (the original's).
MIN_POINT_Z = 0.1

_STATIC = {"dynamic": False}  # read at configure (the cloud is drawn then)

#: Parameters, with the defaults of the original EasyNav's easynav_simple_localizer/AMCLLocalizer.
AMCL_PARAMETERS = (
    Param("num_particles", 100, "number of particles", ge=1, **_STATIC),
    Param("initial_pose.x", 0.0, "initial pose: x (map frame)", "m", **_STATIC),
    Param("initial_pose.y", 0.0, "initial pose: y (map frame)", "m", **_STATIC),
    Param("initial_pose.yaw", 0.0, "initial pose: yaw", "rad", **_STATIC),
    Param("initial_pose.std_dev_xy", 0.5, "initial spread in x and y (σ)", "m", ge=0.0,
          **_STATIC),
    Param("initial_pose.std_dev_yaw", 0.5, "initial spread in yaw (σ)", "rad", ge=0.0,
          **_STATIC),
    Param("reseed_freq", 1.0, "the worse half of the cloud is redrawn at this rate", "Hz",
          gt=0.0),
    Param("noise_translation", 0.01, "prediction noise per metre driven", ge=0.0),
    Param("noise_rotation", 0.01, "prediction noise per radian turned", ge=0.0),
    Param("noise_translation_to_rotation", 0.01, "yaw noise per metre driven", ge=0.0),
    Param("min_noise_xy", 0.05, "σ floor in x and y (reseed, initialpose)", "m", ge=0.0),
    Param("min_noise_yaw", 0.05, "σ floor in yaw (reseed, initialpose)", "rad", ge=0.0),
    # Not in the original (which counted exact hits, sigma 0): see likelihood_field.
    Param("hit_sigma", 0.2, "a point d m from an obstacle counts exp(-d²/2σ²) of a hit (0: exact "
          "hits only, as the original)", "m", ge=0.0),
)


def odometry_increment(
    a: tuple[float, float, float], b: tuple[float, float, float]
) -> tuple[float, float, float]:
    """Planar pose ``b`` in the frame of pose ``a``: the motion from odometry ``a`` to ``b``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return c * dx + s * dy, -s * dx + c * dy, normalize_angle(b[2] - a[2])


def moved_by_increment(poses: np.ndarray, increment: tuple[float, float, float]) -> np.ndarray:
    """The planar ``poses`` ``(N, 3)`` each moved by the odometry ``increment`` ``(dx, dy,
    dyaw)`` taken in its own frame (:func:`odometry_increment`): where a pose estimated at one
    odometry is at a later one."""
    poses = np.asarray(poses, dtype=float).reshape(-1, 3)
    dx, dy, dyaw = increment
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    yaw = (poses[:, 2] + dyaw + math.pi) % (2.0 * math.pi) - math.pi  # [-π, π), as normalize_angle
    return np.column_stack((poses[:, 0] + c * dx - s * dy, poses[:, 1] + s * dx + c * dy, yaw))


def _xy_yaw(pose: Pose) -> tuple[float, float, float]:
    return pose.x, pose.y, pose.yaw


class AMCLLocalizer(LocalizerMethodBase):
    """Monte Carlo localisation on NavState ``map.base`` with odometry from the ``odom`` topic.

    - Prediction (``update_rt``, RT thread): each new odometry increment moves the particles
      (noise ``noise_translation``, ``noise_rotation``, ``noise_translation_to_rotation``, see
      :class:`ParticleFilter2D`), then ``robot_pose`` is written and ``map → odom`` broadcast.
    - Correction (``update``, non-RT thread): the ungrouped point perceptions, fused into the
      robot footprint frame, above z 0.1 m and downsampled to the map resolution, are scored
      per particle by the fraction that hits the obstacle surfaces of ``map.base`` (occupied
      cells near free space, :func:`surface_cells`; a soft hit, see ``hit_sigma`` and
      :func:`likelihood_field`); the weights are
      multiplied by it, the cloud is resampled (low variance) when its effective size drops
      below half, and every ``1/reseed_freq`` s the lower-weight half is redrawn around the
      upper half (at least ``min_noise_xy``/``min_noise_yaw`` apart).

    Parameters: :attr:`PARAMETERS` (defaults of the original). Added here: ``hit_sigma``
    (0.2 m): a point ``d`` metres from the nearest obstacle surface counts ``exp(-d²/2σ²)`` of
    a hit; 0 counts only points on the surfaces, as the original did on occupied cells (it
    converges more slowly and can lock onto a wrong pose). The noise, reseed and ``hit_sigma``
    parameters can change at runtime; the particle count and the initial pose are read at configure.

    NavState: reads ``map.base`` (:class:`SimpleMap`) and every ungrouped
    :class:`PointPerception`; writes ``robot_pose`` (:class:`Odometry` in the map frame, child
    the robot footprint frame, stamp of the odometry used, covariance of the particles, twist of
    the odometry) and ``localizer.amcl.covariance_trace`` (float: var x + var y + var yaw).

    ROS (when hosted by a node): subscribes ``odom`` (nav_msgs/Odometry) on the host's RT-side
    node (``context.rt_node``, spun by the RT loop like the original's RT callback group: a slow
    non-RT loop cannot delay the prediction; the host node without one); ``initialpose``
    (through :class:`LocalizerMethodBase`) resets the cloud (:meth:`on_initial_pose`); publishes
    ``<fqn>/<alias>/particles`` (PoseArray) and ``<fqn>/<alias>/pose``
    (PoseWithCovarianceStamped) after each correction while subscribed; broadcasts ``map → odom``
    on ``tf`` (and into this process's TF buffer, also without a node).

    Thread contract: ``update_rt`` and the ``odom`` callback in the RT thread; ``update``,
    ``initialpose``, :meth:`reset_pose` and ``on_last_known_pose`` from the non-RT side;
    :meth:`set_odometry` from any thread.
    One lock guards the particles; the expensive scoring runs outside it on a snapshot.
    Exceptions: :class:`PluginConfigurationError` naming the parameter.
    """

    NEEDS_MAPS = ("simple_map",)
    PARAMETERS = AMCL_PARAMETERS
    TOPICS = (
        Topic("odom", "nav_msgs/msg/Odometry", "sub", "reliable, keep last 5",
              "wheel odometry (prediction)"),
        Topic("initialpose", "geometry_msgs/msg/PoseWithCovarianceStamped", "sub",
              description="resets the cloud (map frame)"),
        Topic("<node>/<alias>/particles", "geometry_msgs/msg/PoseArray", "pub",
              description="the cloud after each correction, while subscribed"),
        Topic("<node>/<alias>/pose", "geometry_msgs/msg/PoseWithCovarianceStamped", "pub",
              description="the estimate after each correction, while subscribed"),
        Topic("/tf", "tf2_msgs/msg/TFMessage", "pub", description="map → odom"),
    )
    READS = (MAP_BASE,)
    WRITES = (ROBOT_POSE, COVARIANCE_TRACE_KEY)

    def __init__(self) -> None:
        super().__init__()
        self.filter = ParticleFilter2D(1)
        self._lock = threading.Lock()
        self._throttle = WarningThrottle(period=5.0)
        self._odom: Odometry | None = None
        self._odom_used: tuple[float, float, float] | None = None
        self._odom_used_stamp: float | None = None
        self._last_reseed = 0.0
        self._ros: dict = {}
        self._odom_node = None  # where the odom subscription lives (RT-side node or host)
        self._broadcaster = None
        self._field_map: SimpleMap | None = None
        self._field: np.ndarray | None = None
        # Bumped whenever the cloud is redrawn, so a correction scored on the old cloud is dropped.
        self._generation = 0

    # -- configuration ------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        alias = self.plugin_name
        v = self.params
        self.num_particles = v.num_particles
        self._apply_tuning()
        self._field_map = None
        self._field = None
        with self._lock:
            self._generation += 1
            self.filter = ParticleFilter2D(self.num_particles)
            std_xy = v["initial_pose.std_dev_xy"]
            self.filter.seed(
                v["initial_pose.x"],
                v["initial_pose.y"],
                v["initial_pose.yaw"],
                np.eye(2) * std_xy**2,
                v["initial_pose.std_dev_yaw"],
            )
            self._odom = None
            self._odom_used = None
            self._odom_used_stamp = None
        self._last_reseed = self.now()
        self.logger.info(
            f"{alias}: {self.num_particles} particles around ({v['initial_pose.x']:g}, "
            f"{v['initial_pose.y']:g}, {v['initial_pose.yaw']:g}) std "
            f"[{std_xy:g} m, {v['initial_pose.std_dev_yaw']:g} rad]"
        )
        if self.context.node is not None:
            self._create_ros()

    def on_cleanup(self) -> None:
        self._destroy_ros()

    def _apply_tuning(self) -> None:
        # Derived from the parameters that may change at runtime; each a single assignment.
        v = self.params
        self.reseed_period = 1.0 / v.reseed_freq
        self.noise = (v.noise_translation, v.noise_rotation, v.noise_translation_to_rotation)
        self.min_noise_xy = v.min_noise_xy
        self.min_noise_yaw = v.min_noise_yaw
        self.hit_sigma = v.hit_sigma

    def on_parameter_changed(self, name: str, value: object) -> None:
        """Noise, reseed rate and ``hit_sigma`` apply from the next update."""
        self._apply_tuning()
        if name == "hit_sigma":
            self._field_map = None  # the likelihood field is rebuilt with the new sigma

    # -- inputs -------------------------------------------------------------------------------
    def set_odometry(self, odometry: Odometry) -> None:
        """The latest wheel odometry (``odom → robot`` pose). Any thread; non-finite ignored."""
        if not odometry.is_finite():
            self._throttle.warn(
                self.logger, "odom-nan", f"{self.plugin_name}: non-finite odometry ignored"
            )
            return
        self._odom = odometry  # one reference swap: the RT thread reads a whole message

    def reset_pose(
        self, x: float, y: float, yaw: float, cov_xy: np.ndarray, var_yaw: float
    ) -> None:
        """Redraw every particle around ``(x, y, yaw)`` with that covariance (at least the
        minimum noise). Non-RT side (callbacks); serialised with the RT prediction."""
        with self._lock:
            self._generation += 1
            self.filter.seed(
                x,
                y,
                yaw,
                cov_xy,
                math.sqrt(max(var_yaw, 0.0)),
                self.min_noise_xy,
                self.min_noise_yaw,
            )
        self._last_reseed = self.now()
        self.logger.info(
            f"{self.plugin_name}: {len(self.filter)} particles reset around "
            f"({x:.3f}, {y:.3f}, {yaw:.3f})"
        )

    def on_last_known_pose(self, pose: Odometry) -> None:
        """Continue from the pose left by the previous localizer (any type)."""
        cov = np.asarray(pose.pose_covariance, dtype=float).reshape(6, 6)
        self.reset_pose(pose.pose.x, pose.pose.y, pose.pose.yaw, cov[:2, :2], cov[5, 5])

    def on_initial_pose(self, pose: Odometry) -> None:
        """``initialpose`` (checked by the base): redraw the cloud from the message's
        covariance, with the ``min_noise_*`` floors (the original's)."""
        cov = np.asarray(pose.pose_covariance, dtype=float).reshape(6, 6)
        self.reset_pose(pose.pose.x, pose.pose.y, pose.pose.yaw, cov[:2, :2], cov[5, 5])

    # -- prediction (RT) ----------------------------------------------------------------------
    def update_rt(self, nav_state: NavState) -> None:
        """Move the particles by the new odometry; write ``robot_pose``; broadcast ``map → odom``.

        The transform is sent once per odometry message (stamped with it), so the TF tree never
        gets two samples with one stamp; a correction shows in the next one.
        """
        odom = self._odom
        new_odom = odom is not None and odom.header.stamp != self._odom_used_stamp
        with self._lock:
            if new_odom:
                current = _xy_yaw(odom.pose)
                if self._odom_used is not None:
                    self._predict(*odometry_increment(self._odom_used, current))
                self._odom_used = current
                self._odom_used_stamp = odom.header.stamp
            estimate = self.filter.estimate()
            covariance = self.filter.covariance(estimate)
        self._write_pose(nav_state, estimate, covariance, odom)
        if new_odom:
            self._send_map_to_odom(estimate, _xy_yaw(odom.pose), odom.header.stamp)

    def _predict(self, dx: float, dy: float, dyaw: float) -> None:
        """Move the cloud by an odometry increment (robot frame). RT thread, lock held."""
        self.filter.predict(dx, dy, dyaw, *self.noise)

    # -- correction (non-RT) ------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Weigh the particles against the map; resample and reseed; write ``robot_pose``."""
        alias = self.plugin_name
        if not nav_state.has(MAP_KEY):
            self._throttle.warn(self.logger, "no-map", f"{alias}: no '{MAP_KEY}' map yet")
            return
        grid = nav_state.get(MAP_KEY, SimpleMap)
        perceptions = nav_state.get_no_group(PointPerception)
        if not perceptions:
            self._throttle.warn(self.logger, "no-perceptions", f"{alias}: no point perceptions")
            return
        buffer = get_tf_buffer(self.context.namespace)
        frame = buffer.get_tf_info().robot_footprint_frame
        points = (
            PointPerceptionsOps(perceptions, buffer, self.logger)
            .fuse(frame)
            .filter((math.nan, math.nan, MIN_POINT_Z), (math.nan, math.nan, math.nan))
            .collapse((math.nan, math.nan, 0.0))
            .downsample(grid.resolution)
            .as_points()
        )
        if len(points) == 0:
            self._throttle.warn(
                self.logger,
                "no-points",
                f"{alias}: no points to correct with (none above z {MIN_POINT_Z} m in {frame})",
            )
            return
        if grid is not self._field_map:  # map.base is replaced, never mutated: cache per object
            self._field, self._field_map = likelihood_field(grid, self.hit_sigma), grid
        with self._lock:
            snapshot = self.filter.poses.copy()
            generation = self._generation
        # Numpy at the usual sizes: this plugin alone would load numba for it (issue #21).
        compiled = compiled_scoring_pays(len(snapshot), len(points))
        fractions, _ = hit_fractions(snapshot, points[:, :2], grid, self._field, compiled=compiled)
        now = self.now()
        with self._lock:
            if generation == self._generation:  # not redrawn (initialpose) while scoring
                if not self.filter.correct(fractions):
                    self._throttle.warn(
                        self.logger,
                        "no-hits",
                        f"{alias}: no particle explains the scan (no point hits the map)",
                    )
                elif self.filter.effective_sample_size() < 0.5 * len(self.filter):
                    self.filter.resample()
            if now - self._last_reseed >= self.reseed_period or now < self._last_reseed:
                self.filter.reseed_worst_half(self.min_noise_xy, self.min_noise_yaw)
                self._last_reseed = now
            estimate = self.filter.estimate()
            covariance = self.filter.covariance(estimate)
            poses = self.filter.poses.copy()
        self._write_pose(nav_state, estimate, covariance, self._odom)
        self._publish_particles(poses, estimate, covariance)

    # -- outputs ------------------------------------------------------------------------------
    def _write_pose(
        self,
        nav_state: NavState,
        estimate: tuple[float, float, float],
        covariance: np.ndarray,
        odom: Odometry | None,
    ) -> None:
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        x, y, yaw = estimate
        cov6 = np.zeros((6, 6))
        cov6[np.ix_((0, 1, 5), (0, 1, 5))] = covariance
        pose = Odometry(
            header=Header(odom.header.stamp if odom is not None else self.now(), tf_info.map_frame),
            child_frame_id=tf_info.robot_footprint_frame,
            pose=Pose.from_xy_yaw(x, y, yaw),
            pose_covariance=cov6,
            twist=odom.twist if odom is not None else Twist(),
        )
        nav_state.set(POSE_KEY, pose)
        nav_state.set(COVARIANCE_TRACE_KEY, float(np.trace(covariance)))

    def _send_map_to_odom(
        self, estimate: tuple[float, float, float], odom_xy_yaw: tuple, stamp: float
    ) -> None:
        # map→odom = (map→robot)·(odom→robot)⁻¹, all planar.
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        x, y, yaw = estimate
        ox, oy, oyaw = odom_xy_yaw
        t_yaw = normalize_angle(yaw - oyaw)
        c, s = math.cos(t_yaw), math.sin(t_yaw)
        tx, ty = x - (c * ox - s * oy), y - (s * ox + c * oy)
        transform = TransformStamped(
            Header(stamp, tf_info.map_frame),
            tf_info.odom_frame,
            Transform(np.array((tx, ty, 0.0)), np.array(yaw_to_quaternion(t_yaw))),
        )
        if self._broadcaster is not None:
            self._broadcaster.send_transform(transform)
        else:
            get_tf_buffer(self.context.namespace).set_transform(transform, self.plugin_name)

    def _publish_particles(self, poses: np.ndarray, estimate, covariance) -> None:
        particles = self._ros.get("particles")
        estimate_pub = self._ros.get("pose")
        if particles is None:
            return
        from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped

        from easynav.system.ros.converters import header_to_msg, pose_to_msg

        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        odom = self._odom
        header = header_to_msg(Header(odom.header.stamp if odom else self.now(), tf_info.map_frame))
        if particles.get_subscription_count() > 0:
            msg = PoseArray(header=header)
            msg.poses = [pose_to_msg(Pose.from_xy_yaw(*p)) for p in poses.tolist()]
            particles.publish(msg)
        if estimate_pub.get_subscription_count() > 0:
            msg = PoseWithCovarianceStamped(header=header)
            msg.pose.pose = pose_to_msg(Pose.from_xy_yaw(*estimate))
            cov6 = np.zeros((6, 6))
            cov6[np.ix_((0, 1, 5), (0, 1, 5))] = covariance
            msg.pose.covariance = cov6.ravel()
            estimate_pub.publish(msg)

    # -- ROS ----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
        from nav_msgs.msg import Odometry as OdometryMsg
        from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

        from easynav.system.tf import TFBroadcaster

        node = self.context.node
        base = f"{node.get_fully_qualified_name().rstrip('/')}/{self.plugin_name}"
        # The original's SensorDataQoS().reliable(): keep last 5, reliable, volatile.
        odom_qos = QoSProfile(
            history=HistoryPolicy.KEEP_LAST,
            depth=5,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
        # Odometry feeds the RT prediction: served by the RT loop's executor when there is one.
        odom_node = self.context.rt_node if self.context.rt_node is not None else node
        self._odom_node = odom_node
        self._ros = {
            "odom": odom_node.create_subscription(OdometryMsg, "odom", self._on_odom, odom_qos),
            "particles": node.create_publisher(PoseArray, f"{base}/particles", 10),
            "pose": node.create_publisher(PoseWithCovarianceStamped, f"{base}/pose", 10),
        }
        self._broadcaster = TFBroadcaster(node, local_buffer=get_tf_buffer(self.context.namespace))

    def _destroy_ros(self) -> None:
        node = self.context.node
        ros, self._ros = self._ros, {}
        broadcaster, self._broadcaster = self._broadcaster, None
        if node is None:
            return
        for name, entity in ros.items():
            if name == "odom":
                self._odom_node.destroy_subscription(entity)
            else:
                node.destroy_publisher(entity)
        if broadcaster is not None:
            broadcaster.destroy()

    def _on_odom(self, msg) -> None:
        from easynav.system.ros.converters import odometry_from_msg

        self.set_odometry(odometry_from_msg(msg))
