"""FusionLocalizer (easynav_fusion_localizer/FusionLocalizer): robot_localization's UKF."""

from __future__ import annotations

import math
import threading
from collections import deque
from typing import Any, ClassVar

import numpy as np

from easynav.common.sensors import GNSSPerception, ImuPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE, NavStateKey
from easynav.core.plugins import LocalizerMethodBase, Param, PluginConfigurationError, Topic
from easynav.core.plugins.declarations import ParameterValueError
from easynav.core.types import (
    Header,
    Odometry,
    Pose,
    Twist,
)
from easynav.core.warning_throttle import WarningThrottle
from easynav.localizers.fusion.fusion_filter import MAX_LAG, FusionFilter, quaternion_to_rpy
from easynav.localizers.fusion.fusion_parameters import (
    FILTER_PARAMETERS,
    FILTER_PREFIXES,
    is_input_key,
    prefixed,
    read_inputs,
)
from easynav.localizers.fusion.ukf_filter import (
    ROLL,
    VX,
    VY,
    VYAW,
    YAW,
    UkfFilter,
    square_matrix,
)
from easynav.localizers.map_to_odom import PoseHistory, carry_pose, map_to_odom

#: NavState keys.
ROBOT_POSE_LOCAL = NavStateKey(
    "robot_pose_local", "Odometry", "the local filter's estimate (odom frame, continuous)."
)
#: The NavState group the sensors node puts GNSS receivers in (matched to gpsN by order).
GNSS_GROUP = "gnss"
#: A handed-over pose stamped more than this (s) before the first measurement after it is
#: taken as of that measurement (not carried): the TF buffer's default history.
HANDOVER_WINDOW = 10.0

_PLUGIN_PARAMETERS = (
    Param("latitude_origin", 0.0, "geodetic origin of the map frame: latitude", "deg",
          ge=-90.0, le=90.0, dynamic=False),
    Param("longitude_origin", 0.0, "geodetic origin: longitude", "deg", ge=-180.0, le=180.0,
          dynamic=False),
    Param("altitude_origin", 0.0, "geodetic origin: altitude (WGS 84 ellipsoid)", "m",
          dynamic=False),
    Param("navsatfix_topic", "gps/filtered", "NavSatFix of the fused pose (relative)",
          dynamic=False),
)


def _euler_quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, ...]:
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


class FusionLocalizer(LocalizerMethodBase):
    """robot_localization's UKF (15 states) fusing odometry, IMU and GNSS, on filterpy.

    Two filters, each present only when some key under ``<alias>.global_filter.`` /
    ``<alias>.local_filter.`` is set (neither: configure fails). The **global** filter estimates
    the pose in the map frame and writes ``robot_pose``; the **local** one, in the odom frame,
    writes ``robot_pose_local``. Inputs use robot_localization's names: ``odomN``, ``poseN``,
    ``twistN`` and ``imuN`` name topics this plugin subscribes (on the RT-side node); ``gpsN``
    is not subscribed: the N-th member of NavState group ``gnss`` (filled by the sensors node's
    NavSatFix handler) is used. Each input's ``_config`` picks the 15 state variables it
    measures; ``_rejection_threshold`` parameters are Mahalanobis gates (a GNSS jump is
    rejected); with GNSS lost, odometry and IMU carry the estimate on. GNSS fixes become map
    positions through UTM (pyproj, the zone of ``latitude_origin``/``longitude_origin``); the
    first fix initialises the global filter (yaw from the IMU when one was read).

    ``initialpose`` / ``on_last_known_pose``: the filters continue from that pose; GNSS
    positions are shifted so the estimate lands on it (the original moved its UTM origin).

    All work is done in ``update_rt`` (as the original); ``update`` does nothing.

    ROS (when hosted by a node): subscriptions of the inputs' topics on ``context.rt_node``
    (RT thread; callbacks only queue the message); publishes ``global_odometry/filtered`` /
    ``local_odometry/filtered`` (Odometry) and ``navsatfix_topic`` (NavSatFix of the global
    estimate, with a geodetic origin); broadcasts ``map → odom`` (global filter,
    ``publish_tf``) from the estimate and the ``odom → robot`` transform in the TF buffer.

    Thread contract: input callbacks and ``update_rt`` in the RT thread; ``initialpose`` and
    ``on_last_known_pose`` from the non-RT side; :meth:`add_odometry` / :meth:`add_imu` from any
    thread. One lock guards both filters. Exceptions: :class:`PluginConfigurationError`
    naming the parameter at configure; ImportError naming the extra when filterpy or pyproj is
    missing; a bad measurement is dropped with a throttled warning.
    """

    #: Sensors the robot must have (the integration matrix runs it only in worlds that give them).
    NEEDS_SENSORS = ("gnss",)

    NEEDS_MAPS: ClassVar[tuple[str, ...]] = ()
    HAS_UPDATE = False
    PARAMETERS = (
        _PLUGIN_PARAMETERS
        + prefixed("global_filter", FILTER_PARAMETERS)
        + prefixed("local_filter", FILTER_PARAMETERS)
    )
    TOPICS = LocalizerMethodBase.TOPICS + (
        Topic("<odomN|poseN|twistN>", "nav_msgs/msg/Odometry", "sub", "reliable, queue_size",
              "odometry inputs (poseN: PoseWithCovarianceStamped, twistN: "
              "TwistWithCovarianceStamped)"),
        Topic("<imuN>", "sensor_msgs/msg/Imu", "sub", "reliable, queue_size", "IMU inputs"),
        Topic("global_odometry/filtered", "nav_msgs/msg/Odometry", "pub",
              description="the global estimate"),
        Topic("local_odometry/filtered", "nav_msgs/msg/Odometry", "pub",
              description="the local estimate"),
        Topic("<navsatfix_topic>", "sensor_msgs/msg/NavSatFix", "pub",
              description="the global estimate as a fix"),
        Topic("/tf", "tf2_msgs/msg/TFMessage", "pub", description="map → odom (publish_tf)"),
    )
    READS = ()
    WRITES = (ROBOT_POSE, ROBOT_POSE_LOCAL)

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._throttle = WarningThrottle(period=5.0)
        self.filters: dict[str, FusionFilter] = {}
        self._queues: dict[tuple[str, str], deque] = {}
        self._gnss_stamps: dict[tuple[str, str], float] = {}
        self._ros: dict[str, Any] = {}
        self._subscriptions: list[tuple[Any, Any]] = []
        self._broadcaster = None
        self._projection = None
        self._publish_tf = False
        self._predict_now: dict[str, bool] = {}
        self._gravity: dict[str, float] = {}
        #: The pose handed over (``on_last_known_pose``), applied on the next cycle.
        self._handover: Odometry | None = None
        #: The global filter's recent estimates, for ``map → odom`` (RT thread).
        self._history = PoseHistory()

    # -- parameters ----------------------------------------------------------------------------
    @classmethod
    def unknown_parameter_keys(cls, keys):
        """As :meth:`ParameterOwner.unknown_parameter_keys`, accepting every robot_localization
        input key (``odomN``, ``imuN_config``...) under either filter."""
        unknown = super().unknown_parameter_keys(keys)
        return [
            (key, closest) for key, closest in unknown
            if not (key.split(".", 1)[0] in FILTER_PREFIXES and "." in key
                    and is_input_key(key.split(".", 1)[1]))
        ]

    def _filter_is_set(self, prefix: str) -> bool:
        access = self.context.parameters
        base = f"{self.plugin_name}.{prefix}"
        return any(access.is_set(f"{base}.{p.name}") for p in FILTER_PARAMETERS) or any(
            access.is_set(f"{base}.{kind}0") for kind in ("odom", "pose", "twist", "imu", "gps")
        )

    # -- configuration -------------------------------------------------------------------------
    def on_initialize(self) -> None:
        self._destroy_ros()
        alias = self.plugin_name
        v = self.params
        prefixes = [p for p in FILTER_PREFIXES if self._filter_is_set(p)]
        if not prefixes:
            raise PluginConfigurationError(
                f"{alias}: no filter configured: set {alias}.global_filter.* and/or "
                f"{alias}.local_filter.* (robot_localization parameters)"
            )
        filters: dict[str, FusionFilter] = {}
        queues: dict[tuple[str, str], deque] = {}
        projection = None
        for prefix in prefixes:
            try:
                inputs = read_inputs(self.context.parameters, f"{alias}.{prefix}",
                                     warn=self.logger.error)
            except ParameterValueError as exc:
                raise PluginConfigurationError(str(exc)) from None
            if prefix == "local_filter" and any(i.kind == "gps" for i in inputs):
                raise PluginConfigurationError(
                    f"{alias}.local_filter.gps0: GNSS inputs belong to the global filter"
                )
            if any(i.kind == "gps" for i in inputs) and projection is None:
                from easynav.localizers.fusion.utm_projection import UtmProjection

                try:
                    projection = UtmProjection(v.latitude_origin, v.longitude_origin,
                                               v.altitude_origin)
                except ValueError as exc:
                    raise PluginConfigurationError(f"{alias}.latitude_origin: {exc}") from None
            try:
                ukf = UkfFilter(
                    alpha=v[f"{prefix}.alpha"], beta=v[f"{prefix}.beta"],
                    kappa=v[f"{prefix}.kappa"],
                    process_noise=square_matrix(v[f"{prefix}.process_noise_covariance"],
                                                f"{alias}.{prefix}.process_noise_covariance"),
                    initial_covariance=square_matrix(
                        v[f"{prefix}.initial_estimate_covariance"],
                        f"{alias}.{prefix}.initial_estimate_covariance"),
                    initial_state=self._initial_state(prefix),
                    two_d_mode=v[f"{prefix}.two_d_mode"],
                )
            except ValueError as exc:
                raise PluginConfigurationError(str(exc)) from None
            filters[prefix] = FusionFilter(ukf, inputs, projection)
            self._predict_now[prefix] = v[f"{prefix}.predict_to_current_time"]
            self._gravity[prefix] = v[f"{prefix}.gravitational_acceleration"]
            for source in inputs:
                if source.kind != "gps":
                    queues[(prefix, source.name)] = deque(maxlen=source.queue_size)
            self.logger.info(
                f"{alias}: {prefix} fuses "
                + (", ".join(f"{i.name} ({i.topic or 'NavState gnss'})" for i in inputs)
                   or "nothing")
            )
        with self._lock:
            self.filters = filters
            self._queues = queues
            self._gnss_stamps = {}
            self._projection = projection
            self._handover = None
            self._history.clear()
        self._publish_tf = "global_filter" in filters and v["global_filter.publish_tf"]
        if self.context.node is not None:
            self._create_ros()

    def _initial_state(self, prefix: str) -> np.ndarray:
        state = np.asarray(self.params[f"{prefix}.initial_state"], dtype=float)
        if state.size != 15:
            raise PluginConfigurationError(
                f"{self.plugin_name}.{prefix}.initial_state: {state.size} values, expected 15"
            )
        return state

    def on_cleanup(self) -> None:
        self._destroy_ros()

    # -- inputs --------------------------------------------------------------------------------
    def add_odometry(self, prefix: str, name: str, odometry: Odometry) -> None:
        """Queue an ``odomN``/``poseN``/``twistN`` message for filter ``prefix``. Any thread."""
        queue = self._queues.get((prefix, name))
        if queue is not None:
            queue.append(odometry)  # deque.append is atomic

    def add_imu(self, prefix: str, name: str, imu: ImuPerception) -> None:
        """Queue an ``imuN`` reading for filter ``prefix``. Any thread."""
        queue = self._queues.get((prefix, name))
        if queue is not None:
            queue.append(imu)

    def on_last_known_pose(self, pose: Odometry) -> None:
        """Continue from ``pose`` (map frame): the global filter jumps there (GNSS shifted to
        agree, once a fix has placed the filter), the local filter keeps its odom-frame
        estimate. The jump happens in the next cycle (a fresh filter: the next one with
        measurements): the pose is first carried by the odometry from its stamp to the first
        measurement (:func:`carry_pose`), since the robot may have driven on in between (a
        reconfiguration takes a second or more). A stamp of 0, or one more than 10 s before
        or 1 s after the measurements (another clock), is taken as "now"."""
        with self._lock:
            self._handover = pose
        self.logger.info(
            f"{self.plugin_name}: continuing from ({pose.pose.x:.3f}, {pose.pose.y:.3f}, "
            f"{pose.pose.yaw:.3f}) at t={pose.header.stamp:.3f}"
        )

    def _take_over(self, filt: FusionFilter, events: list, buffer) -> list:
        """Apply the pending handover to the global filter ``filt`` before ``events`` (sorted)
        are fused; returns the events left to fuse (those older than the pose describe motion
        it already includes). A fresh filter without events waits for them; a running one
        takes the pose at its own time. Under the lock."""
        pose = self._handover
        if events:
            reference = events[0][0]
        elif filt.time is not None:
            reference = filt.time
        else:
            return events
        self._handover = None
        stamp = pose.header.stamp
        if not reference - HANDOVER_WINDOW <= stamp <= reference + MAX_LAG:
            # Unstamped (0), or on another clock (an initialpose from a tool on wall time
            # while the robot runs on simulated time): the pose is taken as of now.
            stamp = 0.0
        until = max(stamp, reference)
        events = [e for e in events if e[0] >= until]
        # The motion between the pose's stamp and ``until`` at constant velocity, when no
        # odometry transforms cover it: the pose's own, or the running filter's (an
        # initialpose has none).
        twist = (pose.twist.vx, pose.twist.vy, pose.twist.wz)
        if filt.time is not None and filt.initialized:
            state = filt.ukf.state
            twist = (float(state[VX]), float(state[VY]), float(state[VYAW]))
        x, y, yaw = carry_pose(buffer, pose.pose.x, pose.pose.y, pose.pose.yaw, stamp, until,
                               twist)
        if stamp > 0.0 and until > stamp:
            self.logger.info(
                f"{self.plugin_name}: the pose of t={stamp:.3f} carried to t={until:.3f}: "
                f"({x:.3f}, {y:.3f}, {yaw:.3f})")
        cov = np.asarray(pose.pose_covariance, dtype=float).reshape(6, 6)
        self._history.clear()  # the estimates before the jump no longer hold
        filt.reset_pose(x, y, yaw, cov, time=until,
                        twist=(pose.twist.vx, pose.twist.vy, pose.twist.wz))
        return events

    # -- cycle ---------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Nothing: the original does all its work in ``update_rt``."""

    def update_rt(self, nav_state: NavState) -> None:
        """Fuse every queued measurement and the new GNSS fixes, in time order, into each
        filter; write ``robot_pose`` / ``robot_pose_local``; broadcast ``map → odom``."""
        fixes = self._gnss_fixes(nav_state)
        now = self.now()
        outputs = {}
        buffer = get_tf_buffer(self.context.namespace)
        tf_info = buffer.get_tf_info()
        with self._lock:
            for prefix, filt in self.filters.items():
                events = []
                for (p, name), queue in self._queues.items():
                    if p != prefix:
                        continue
                    while queue:
                        value = queue.popleft()
                        stamp = (value.header.stamp if isinstance(value, Odometry)
                                 else value.stamp)
                        events.append((stamp, name, value))
                for name, fix in fixes.items():
                    key = (prefix, name)
                    if name in filt.inputs and self._gnss_stamps.get(key) != fix.stamp:
                        self._gnss_stamps[key] = fix.stamp
                        events.append((fix.stamp, name, fix))
                events.sort(key=lambda e: e[0])
                if prefix == "global_filter" and self._handover is not None:
                    events = self._take_over(filt, events, buffer)
                for _, name, value in events:
                    try:
                        if isinstance(value, Odometry):
                            filt.add_odometry(name, value, self._robot_in_child(
                                buffer, tf_info.robot_footprint_frame, filt.inputs[name],
                                value))
                        elif isinstance(value, ImuPerception):
                            filt.add_imu(name, value, self._gravity[prefix])
                        elif not filt.add_gnss(name, value) and value.has_fix:
                            if filt.rejected.get(name):
                                self._throttle.warn(
                                    self.logger, f"{prefix}-{name}-gate",
                                    f"{self.plugin_name}: {prefix} rejected a {name} fix "
                                    f"(Mahalanobis gate)")
                    except ValueError as exc:
                        self._throttle.warn(self.logger, f"{prefix}-{name}",
                                            f"{self.plugin_name}: {prefix}: {exc}: dropped")
                if self._predict_now[prefix] and filt.time is not None:
                    filt.predict_to(now)
                if filt.initialized and filt.time is not None:
                    outputs[prefix] = (filt.ukf.state, filt.ukf.covariance, filt.time)
        for prefix, (state, cov, stamp) in outputs.items():
            frame = tf_info.map_frame if prefix == "global_filter" else tf_info.odom_frame
            odometry = self._odometry(state, cov, stamp, frame, tf_info.robot_footprint_frame)
            nav_state.set(ROBOT_POSE if prefix == "global_filter" else ROBOT_POSE_LOCAL,
                          odometry)
            self._publish(prefix, odometry)
        if "global_filter" in outputs:
            state, _, stamp = outputs["global_filter"]
            self._history.add(stamp, state[0], state[1], state[YAW])
            if self._publish_tf:
                self._send_map_to_odom(state, stamp)

    def _robot_in_child(self, buffer, robot_frame: str, source, odometry: Odometry):
        """For an ``odomN`` with ``_pose_use_child_frame`` whose child frame is not the robot
        frame: the robot frame's pose in the child frame (TF ``child → robot`` at the
        message's stamp, else the latest, as robot_localization's lookupTransformSafe);
        None otherwise or when TF has no such transform (the pose is then taken as the
        robot's, as the original does, with a throttled warning)."""
        child = odometry.child_frame_id.lstrip("/")
        if not source.pose_use_child_frame or not child or child == robot_frame.lstrip("/"):
            return None
        for stamp in (odometry.header.stamp, None):
            try:
                _, (x, y, z, qx, qy, qz, qw) = buffer.lookup_transform_values(
                    child, robot_frame, stamp)
            except LookupError:
                continue
            return np.array((x, y, z, *quaternion_to_rpy(qx, qy, qz, qw)))
        self._throttle.warn(
            self.logger, f"{source.name}-child-frame",
            f"{self.plugin_name}: {source.name}_pose_use_child_frame: no transform "
            f"{child} → {robot_frame}: the pose is used as the robot's")
        return None

    def _gnss_fixes(self, nav_state: NavState) -> dict[str, GNSSPerception]:
        # gpsN is the N-th member (in the group's order) holding a GNSSPerception.
        if GNSS_GROUP not in nav_state.groups():
            return {}
        members = nav_state.groups()[GNSS_GROUP]
        values = nav_state.get_group(GNSS_GROUP)
        fixes = [values[m] for m in members if isinstance(values.get(m), GNSSPerception)]
        return {f"gps{n}": fix for n, fix in enumerate(fixes)}

    # -- outputs -------------------------------------------------------------------------------
    @staticmethod
    def _odometry(state, cov, stamp, frame, child) -> Odometry:
        qx, qy, qz, qw = _euler_quaternion(*state[ROLL:YAW + 1])
        return Odometry(
            header=Header(stamp, frame),
            child_frame_id=child,
            pose=Pose(float(state[0]), float(state[1]), float(state[2]), qx, qy, qz, qw),
            pose_covariance=cov[:6, :6].copy(),
            twist=Twist(*(float(v) for v in state[6:12])),
            twist_covariance=cov[6:12, 6:12].copy(),
        )

    def _send_map_to_odom(self, state: np.ndarray, stamp: float) -> None:
        buffer = get_tf_buffer(self.context.namespace)
        try:
            transform = map_to_odom(buffer, float(state[0]), float(state[1]),
                                    float(state[YAW]), stamp,
                                    twist=(state[VX], state[VY], state[VYAW]),
                                    history=self._history)
        except Exception as exc:  # no odometry transform yet: nothing to anchor map → odom on
            self._throttle.warn(self.logger, "no-odom-tf",
                                f"{self.plugin_name}: no map → odom: {exc}")
            return
        if self._broadcaster is not None:
            self._broadcaster.send_transform(transform)
        else:
            buffer.set_transform(transform, self.plugin_name)

    def _publish(self, prefix: str, odometry: Odometry) -> None:
        publisher = self._ros.get(prefix)
        if publisher is None:
            return
        from easynav.system.ros.converters import odometry_to_msg

        if publisher.get_subscription_count() > 0:
            publisher.publish(odometry_to_msg(odometry))
        fix_pub = self._ros.get("navsatfix")
        if (prefix == "global_filter" and fix_pub is not None and self._projection is not None
                and fix_pub.get_subscription_count() > 0):
            from sensor_msgs.msg import NavSatFix, NavSatStatus

            from easynav.system.ros.converters import header_to_msg

            filt = self.filters["global_filter"]
            east = odometry.pose.x - filt.gnss_offset[0]
            north = odometry.pose.y - filt.gnss_offset[1]
            lat, lon = self._projection.inverse(east, north)
            msg = NavSatFix(header=header_to_msg(odometry.header))
            msg.status.status = NavSatStatus.STATUS_FIX
            msg.latitude, msg.longitude = lat, lon
            msg.altitude = odometry.pose.z + self._projection.altitude
            msg.position_covariance = odometry.pose_covariance[:3, :3].ravel().tolist()
            msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_KNOWN
            fix_pub.publish(msg)

    # -- ROS -----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from nav_msgs.msg import Odometry as OdometryMsg
        from sensor_msgs.msg import Imu, NavSatFix

        from easynav.system.tf import TFBroadcaster

        node = self.context.node
        sub_node = self.context.rt_node if self.context.rt_node is not None else node
        for prefix, filt in self.filters.items():
            short = prefix.split("_")[0]
            self._ros[prefix] = node.create_publisher(OdometryMsg, f"{short}_odometry/filtered",
                                                      10)
            for source in filt.inputs.values():
                if source.kind == "gps" or not source.topic:
                    continue
                sub = self._subscribe(sub_node, prefix, source, OdometryMsg, Imu)
                self._subscriptions.append((sub_node, sub))
        if "global_filter" in self.filters and self._projection is not None:
            self._ros["navsatfix"] = node.create_publisher(NavSatFix, self.params.navsatfix_topic,
                                                           10)
        if self._publish_tf:
            self._broadcaster = TFBroadcaster(
                node, local_buffer=get_tf_buffer(self.context.namespace))

    def _subscribe(self, sub_node, prefix, source, odometry_type, imu_type):
        from easynav.system.ros.converters import odometry_from_msg
        from easynav.system.sensors.converters.imu import imu_from_msg

        name = source.name
        if source.kind == "imu":
            def on_imu(msg):
                try:
                    self.add_imu(prefix, name, imu_from_msg(msg))
                except Exception as exc:  # a callback must not end the executor's spin
                    self._throttle.warn(self.logger, f"{name}-msg", f"{name}: {exc}")
            return sub_node.create_subscription(imu_type, source.topic, on_imu,
                                                source.queue_size)
        if source.kind == "odom":
            def on_odom(msg):
                self.add_odometry(prefix, name, odometry_from_msg(msg))
            return sub_node.create_subscription(odometry_type, source.topic, on_odom,
                                                source.queue_size)
        if source.kind == "pose":
            from geometry_msgs.msg import PoseWithCovarianceStamped

            from easynav.system.ros.converters import pose_from_msg, time_from_msg

            def on_pose(msg):
                self.add_odometry(prefix, name, Odometry(
                    header=Header(time_from_msg(msg.header.stamp), msg.header.frame_id),
                    pose=pose_from_msg(msg.pose.pose),
                    pose_covariance=np.array(msg.pose.covariance, dtype=float).reshape(6, 6)))
            return sub_node.create_subscription(PoseWithCovarianceStamped, source.topic,
                                                on_pose, source.queue_size)
        from geometry_msgs.msg import TwistWithCovarianceStamped

        from easynav.system.ros.converters import time_from_msg

        def on_twist(msg):
            t = msg.twist.twist
            self.add_odometry(prefix, name, Odometry(
                header=Header(time_from_msg(msg.header.stamp), msg.header.frame_id),
                twist=Twist(t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y,
                            t.angular.z),
                twist_covariance=np.array(msg.twist.covariance, dtype=float).reshape(6, 6)))
        return sub_node.create_subscription(TwistWithCovarianceStamped, source.topic, on_twist,
                                            source.queue_size)

    def _destroy_ros(self) -> None:
        node = self.context.node
        ros, self._ros = self._ros, {}
        subscriptions, self._subscriptions = self._subscriptions, []
        broadcaster, self._broadcaster = self._broadcaster, None
        if node is None:
            return
        for sub_node, sub in subscriptions:
            sub_node.destroy_subscription(sub)
        for publisher in ros.values():
            node.destroy_publisher(publisher)
        if broadcaster is not None:
            broadcaster.destroy()



