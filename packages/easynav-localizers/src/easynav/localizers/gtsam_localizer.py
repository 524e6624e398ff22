"""GtsamLocalizer (easynav_gtsam_localizer/GtsamLocalizer): fixed-lag factor-graph smoothing of
odometry, IMU heading and GNSS."""

from __future__ import annotations

import math
import threading
from collections import deque
from typing import Any, ClassVar

import numpy as np

from easynav.common.sensors import GNSSPerception, ImuPerception
from easynav.common.sensors.gnss_perception import COVARIANCE_TYPE_DIAGONAL_KNOWN
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE
from easynav.core.plugins import LocalizerMethodBase, Param, Topic
from easynav.core.types import (
    Header,
    Odometry,
    Pose,
    quaternion_to_yaw,
)
from easynav.core.warning_throttle import WarningThrottle
from easynav.localizers.fusion_localizer import GNSS_GROUP
from easynav.localizers.map_to_odom import map_to_odom

_STATIC = {"dynamic": False}


class GtsamLocalizer(LocalizerMethodBase):
    """Planar localisation by GTSAM's iSAM2 fixed-lag smoother (see
    :class:`~easynav.localizers.gtsam.factor_graph_estimator.FactorGraphEstimator`).

    Keyframes every ``keyframe_period`` s and at every GNSS fix, joined by odometry
    between-factors; the IMU heading is a yaw prior; GNSS fixes (the first member of NavState
    group ``gnss``, UTM via pyproj around ``latitude_origin``/``longitude_origin``) are
    position priors with a robust noise model (``robust``, ``robust_k``) so jumps get no
    weight; a fix that arrives after later odometry goes on the keyframe of its stamp, moved by
    the odometry between; a window of ``lag`` s keeps the cost flat over hours. ``robot_pose``
    carries the last keyframe's marginal covariance. ``initialpose`` / ``on_last_known_pose``
    re-anchor the graph (GNSS shifted to agree).

    ROS: subscribes ``odom_topic`` (Odometry) and ``imu_topic`` (Imu) on the RT-side node;
    broadcasts ``map → odom`` from the estimate and the ``odom → robot`` TF. All work in
    ``update_rt``.

    Thread contract: callbacks only queue; ``update_rt`` (RT thread) runs the smoother under a
    lock shared with ``on_last_known_pose``. Exceptions: ImportError naming the extra without
    gtsam or pyproj; PluginConfigurationError for a bad origin or a ``lag`` shorter than two
    keyframe periods.
    """

    #: Sensors the robot must have (the integration matrix runs it only in worlds that give them).
    NEEDS_SENSORS = ("gnss",)

    NEEDS_MAPS: ClassVar[tuple[str, ...]] = ()
    HAS_UPDATE = False
    PARAMETERS = (
        Param("latitude_origin", 0.0, "geodetic origin of the map frame: latitude", "deg",
              ge=-90.0, le=90.0, **_STATIC),
        Param("longitude_origin", 0.0, "geodetic origin: longitude", "deg", ge=-180.0,
              le=180.0, **_STATIC),
        Param("altitude_origin", 0.0, "geodetic origin: altitude", "m", **_STATIC),
        Param("odom_topic", "odom", "wheel odometry (between-factors)", **_STATIC),
        Param("imu_topic", "imu/data", "IMU (heading prior)", **_STATIC),
        Param("lag", 5.0, "fixed-lag window", "s", gt=0.0, **_STATIC),
        Param("keyframe_period", 0.2, "a keyframe at least this often", "s", gt=0.0, **_STATIC),
        Param("odom_sigma_xy", 0.05, "odometry σ per metre travelled", gt=0.0, **_STATIC),
        Param("odom_sigma_yaw", 0.05, "odometry yaw σ per radian turned", gt=0.0, **_STATIC),
        Param("imu_yaw_sigma", 0.0, "IMU heading σ (0: the message's covariance)", "rad",
              ge=0.0, **_STATIC),
        Param("gnss_sigma", 0.0, "GNSS σ per axis (0: the fix's covariance, else 1 m)", "m",
              ge=0.0, **_STATIC),
        Param("robust", "cauchy", "robust noise model of GNSS priors",
              choices=("cauchy", "huber", "tukey", "none"), **_STATIC),
        Param("robust_k", 3.0, "robust kernel scale (σ units)", gt=0.0, **_STATIC),
    )
    TOPICS = LocalizerMethodBase.TOPICS + (
        Topic("<odom_topic>", "nav_msgs/msg/Odometry", "sub", description="wheel odometry"),
        Topic("<imu_topic>", "sensor_msgs/msg/Imu", "sub", description="IMU heading"),
        Topic("/tf", "tf2_msgs/msg/TFMessage", "pub", description="map → odom"),
    )
    WRITES = (ROBOT_POSE,)

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._throttle = WarningThrottle(period=5.0)
        self._queue: deque = deque(maxlen=200)
        self._subs: list = []
        self._broadcaster = None
        self._fix_stamp: float | None = None
        self._offset = np.zeros(2)
        self.estimator = None
        self._projection = None
        self._stamp = 0.0
        # The pose is the last keyframe plus the odometry since: it is the robot at the last
        # odometry message's stamp, moving at that message's twist (body frame).
        self._odom_stamp: float | None = None
        self._twist: tuple[float, float, float] | None = None
        self._failures_seen = 0

    def on_initialize(self) -> None:
        from easynav.core.plugins import PluginConfigurationError
        from easynav.localizers.fusion.utm_projection import UtmProjection
        from easynav.localizers.gtsam.factor_graph_estimator import FactorGraphEstimator

        self._destroy_ros()
        v = self.params
        try:
            projection = UtmProjection(v.latitude_origin, v.longitude_origin, v.altitude_origin)
        except ValueError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}.latitude_origin: {exc}") from None
        try:
            estimator = FactorGraphEstimator(
                lag=v.lag, keyframe_period=v.keyframe_period, odom_sigma_xy=v.odom_sigma_xy,
                odom_sigma_yaw=v.odom_sigma_yaw, robust=v.robust, robust_k=v.robust_k)
        except ValueError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}.lag: {exc}") from None
        with self._lock:
            self._projection = projection
            self.estimator = estimator
            self._queue.clear()
            self._offset = np.zeros(2)
            self._fix_stamp = None
            self._odom_stamp = None
            self._twist = None
            self._failures_seen = 0
        if self.context.node is not None:
            self._create_ros()

    def on_cleanup(self) -> None:
        self._destroy_ros()

    # -- inputs --------------------------------------------------------------------------------
    def add_odometry(self, odometry: Odometry) -> None:
        """Queue an odometry message. Any thread."""
        self._queue.append(odometry)

    def add_imu(self, imu: ImuPerception) -> None:
        """Queue an IMU reading. Any thread."""
        self._queue.append(imu)

    def on_last_known_pose(self, pose: Odometry) -> None:
        """Re-anchor the graph at ``pose``; later GNSS positions shifted to agree."""
        cov = np.asarray(pose.pose_covariance, dtype=float).reshape(6, 6)
        with self._lock:
            current = self.estimator.pose()
            if current is not None:
                self._offset += np.array((pose.pose.x - current[0], pose.pose.y - current[1]))
            self.estimator.reset(self._stamp, pose.pose.x, pose.pose.y, pose.pose.yaw,
                                 np.maximum(cov[np.ix_((0, 1, 5), (0, 1, 5))], 0.0)
                                 + np.eye(3) * 1e-6)

    # -- cycle ---------------------------------------------------------------------------------
    def update(self, nav_state: NavState) -> None:
        """Nothing: the work is done in ``update_rt``."""

    def update_rt(self, nav_state: NavState) -> None:
        """Feed queued odometry/IMU and a new GNSS fix to the smoother; write ``robot_pose``."""
        fix = self._new_fix(nav_state)
        with self._lock:
            events = []
            while self._queue:
                value = self._queue.popleft()
                stamp = value.header.stamp if isinstance(value, Odometry) else value.stamp
                events.append((stamp, 0, value))
            if fix is not None:
                events.append((fix.stamp, 1, fix))
            events.sort(key=lambda e: (e[0], e[1]))
            for stamp, _, value in events:
                self._stamp = max(self._stamp, stamp)
                if isinstance(value, Odometry):
                    if value.pose.is_finite():
                        p = value.pose
                        self.estimator.add_odometry(stamp, p.x, p.y, p.yaw)
                        self._odom_stamp = stamp
                        t = value.twist
                        if all(math.isfinite(v) for v in (t.vx, t.vy, t.wz)):
                            self._twist = (t.vx, t.vy, t.wz)
                elif isinstance(value, ImuPerception):
                    if value.has_orientation and np.all(np.isfinite(value.orientation)):
                        sigma = self.params.imu_yaw_sigma or math.sqrt(
                            max(float(value.orientation_covariance[2, 2]), 1e-6))
                        self.estimator.add_imu_yaw(quaternion_to_yaw(*value.orientation), sigma)
                else:
                    self._add_fix(value)
            pose = self.estimator.pose()
            cov = self.estimator.covariance()
            failures, failure = self.estimator.solver_failures, self.estimator.last_failure
        if failures > self._failures_seen:
            self._failures_seen = failures
            self._throttle.warn(self.logger, "solver", (
                f"{self.plugin_name}: GTSAM failed ({failure}); the graph is anchored again at "
                f"the last estimate ({failures} time(s) so far)"))
        if pose is None:
            self._throttle.warn(self.logger, "no-fix", f"{self.plugin_name}: no GNSS fix yet")
            return
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        cov6 = np.eye(6)
        cov6[np.ix_((0, 1, 5), (0, 1, 5))] = cov
        nav_state.set(ROBOT_POSE, Odometry(
            header=Header(self._stamp, tf_info.map_frame),
            child_frame_id=tf_info.robot_footprint_frame,
            pose=Pose.from_xy_yaw(*pose), pose_covariance=cov6))
        self._send_map_to_odom(pose, self._odom_stamp if self._odom_stamp is not None
                               else self._stamp)

    def _new_fix(self, nav_state: NavState) -> GNSSPerception | None:
        if GNSS_GROUP not in nav_state.groups():
            return None
        values = nav_state.get_group(GNSS_GROUP)
        fixes = [values[m] for m in nav_state.groups()[GNSS_GROUP]
                 if isinstance(values.get(m), GNSSPerception)]
        if not fixes or fixes[0].stamp == self._fix_stamp or not fixes[0].has_fix:
            return None
        self._fix_stamp = fixes[0].stamp
        return fixes[0]

    def _add_fix(self, fix: GNSSPerception) -> None:
        east, north = self._projection.forward(fix.latitude, fix.longitude)
        sigma = self.params.gnss_sigma
        if sigma > 0.0:
            sx = sy = sigma
        elif fix.position_covariance_type >= COVARIANCE_TYPE_DIAGONAL_KNOWN:
            cov = np.asarray(fix.position_covariance, dtype=float).reshape(3, 3)
            sx, sy = math.sqrt(max(cov[0, 0], 1e-6)), math.sqrt(max(cov[1, 1], 1e-6))
        else:
            sx = sy = 1.0
        self.estimator.add_gnss(fix.stamp, east + self._offset[0], north + self._offset[1],
                                sx, sy)

    def _send_map_to_odom(self, pose, stamp: float) -> None:
        buffer = get_tf_buffer(self.context.namespace)
        try:
            transform = map_to_odom(buffer, pose[0], pose[1], pose[2], stamp, twist=self._twist)
        except Exception:  # no odometry transform (yet): nothing to anchor map → odom on
            return
        if self._broadcaster is not None:
            self._broadcaster.send_transform(transform)
        else:
            buffer.set_transform(transform, self.plugin_name)

    # -- ROS -----------------------------------------------------------------------------------
    def _create_ros(self) -> None:
        from nav_msgs.msg import Odometry as OdometryMsg
        from sensor_msgs.msg import Imu

        from easynav.system.ros.converters import odometry_from_msg
        from easynav.system.sensors.converters.imu import imu_from_msg
        from easynav.system.tf import TFBroadcaster

        node = self.context.node
        sub_node = self.context.rt_node if self.context.rt_node is not None else node

        def on_imu(msg: Any) -> None:
            try:
                self.add_imu(imu_from_msg(msg))
            except Exception as exc:  # a callback must not end the executor's spin
                self._throttle.warn(self.logger, "imu", f"{self.plugin_name}: IMU: {exc}")

        self._subs = [
            (sub_node, sub_node.create_subscription(
                OdometryMsg, self.params.odom_topic,
                lambda m: self.add_odometry(odometry_from_msg(m)), 10)),
            (sub_node, sub_node.create_subscription(Imu, self.params.imu_topic, on_imu, 10)),
        ]
        self._broadcaster = TFBroadcaster(node, local_buffer=get_tf_buffer(self.context.namespace))

    def _destroy_ros(self) -> None:
        subs, self._subs = self._subs, []
        broadcaster, self._broadcaster = self._broadcaster, None
        for sub_node, sub in subs:
            sub_node.destroy_subscription(sub)
        if broadcaster is not None:
            broadcaster.destroy()
