"""GpsLocalizer (easynav_gps_localizer/GpsLocalizer): pose from GNSS and an IMU."""

from __future__ import annotations

import math
import threading
from typing import Any, ClassVar

import numpy as np

from easynav.common.sensors import GNSSPerception, ImuPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE
from easynav.core.plugins import LocalizerMethodBase, Param, Topic
from easynav.core.types import (
    Header,
    Odometry,
    Pose,
    Transform,
    TransformStamped,
    Twist,
    normalize_angle,
    quaternion_to_yaw,
    yaw_to_quaternion,
)
from easynav.core.warning_throttle import WarningThrottle
from easynav.localizers.gps.gps_pose_estimator import (
    CLOCK_JUMP,
    GATE_RELEASE,
    GpsPoseEstimator,
)

#: The original's fixed topics (relative; not parameters, not through the sensors node).
FIX_TOPIC = "robot/gps/fix"
IMU_TOPIC = "imu/data"
ODOM_TOPIC = "robot/odom_gps"

_STATIC = {"dynamic": False}


def _rpy_quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    import math

    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


#: How long (s) a fix ahead of the newest ``odom → robot`` waits for odometry before
#: ``map → odom`` is anchored on the latest odometry instead.
ODOMETRY_WAIT = 0.5
#: Wheel odometry's position error per metre driven (σ, m/m), added to ``robot_pose``'s
#: position variance for the way driven since the last fix: a few per cent is typical of wheel
#: odometry on good floors (the playground's drifts about 1 %); through a 15 s outage at
#: 0.5 m/s that is 0.4 m, where the fix's 0.15 m alone would claim the pose as sure as a fix.
ODOMETRY_DRIFT = 0.05


def _anchor_on(pose: tuple[float, float, float], odom: tuple[float, float, float],
               odom_yaw: float) -> tuple[float, float, float]:
    """``map → odom`` (x, y, yaw) such that ``map → odom → robot`` is ``pose`` (x, y, yaw),
    given ``odom → robot``'s position ``odom[:2]`` at the pose's instant and its yaw
    ``odom_yaw`` at the instant of the pose's yaw."""
    t_yaw = normalize_angle(pose[2] - odom_yaw)
    c, s = math.cos(t_yaw), math.sin(t_yaw)
    return pose[0] - (c * odom[0] - s * odom[1]), pose[1] - (s * odom[0] + c * odom[1]), t_yaw


def _compose(anchor: tuple[float, float, float],
             odom: tuple[float, float, float]) -> tuple[float, float, float]:
    """``map → odom`` ``anchor`` applied to ``odom → robot`` ``odom``: the robot in the map."""
    c, s = math.cos(anchor[2]), math.sin(anchor[2])
    return (anchor[0] + c * odom[0] - s * odom[1], anchor[1] + s * odom[0] + c * odom[1],
            normalize_angle(anchor[2] + odom[2]))


class GpsLocalizer(LocalizerMethodBase):
    """The original GPS localizer, with a covariance and the filtered yaw fed back.

    Position: UTM of each fix minus UTM of the first (pyproj, the first fix's zone; no
    altitude), shifted so the first fix lands on ``initial_pose.x/.y`` when set. Yaw: a
    complementary filter of the IMU's gyro and orientation (see :class:`GpsPoseEstimator`);
    roll and pitch from the IMU. ``robot_pose`` carries a covariance (the fix's, the yaw
    filter's) and the IMU's angular velocity as twist.

    NavState: writes ``robot_pose`` in ``update`` (non-RT; ``update_rt`` does nothing, as the
    original): the last fix carried on by odometry to the newest ``odom → robot`` (through
    ``map → odom``), with the position variance grown by :data:`ODOMETRY_DRIFT` for the way
    driven since; the original wrote the last fix as it was, which stood still between fixes
    and through an outage (7.5 m behind the robot after the campus's 15 s one).
    ROS: subscribes ``robot/gps/fix`` (NavSatFix) and ``imu/data`` (Imu) with
    sensor-data QoS made reliable; publishes ``robot/odom_gps`` (Odometry); broadcasts
    ``map → odom`` from the estimate (the original: a static identity); ``initialpose`` moves
    the estimate (later fixes shifted to agree). Fixes that jump away from the estimate are
    rejected (``fix_gate_speed``; not in the original).
    Without ROS, :meth:`add_fix` and :meth:`add_imu` feed it.

    Thread contract: subscription callbacks and ``update`` on the non-RT side; one lock guards
    the estimator. Exceptions: ImportError naming the extra without pyproj (at the first fix);
    a bad message is dropped with a throttled warning.
    """

    #: Sensors the robot must have (the integration matrix runs it only in worlds that give them).
    NEEDS_SENSORS = ("gnss",)

    NEEDS_MAPS: ClassVar[tuple[str, ...]] = ()
    HAS_RT_UPDATE = False
    PARAMETERS = (
        Param("initial_pose.x", 0.0, "where the first fix lands: x (map frame)", "m", **_STATIC),
        Param("initial_pose.y", 0.0, "where the first fix lands: y (map frame)", "m", **_STATIC),
        Param("initial_pose.yaw", 0.0, "unused (yaw comes from the IMU), as the original", "rad",
              **_STATIC),
        Param("fix_gate_speed", 5.0,
              "a fix farther than this speed times the time since the last fix taken (plus 5 "
              "sigma of its noise) is rejected as a jump, unless 5 in a row are; 0: every fix "
              "is taken (the original)", "m/s", ge=0.0, **_STATIC),
    )
    TOPICS = LocalizerMethodBase.TOPICS + (
        Topic(FIX_TOPIC, "sensor_msgs/msg/NavSatFix", "sub", "sensor data, reliable",
              "GNSS fixes"),
        Topic(IMU_TOPIC, "sensor_msgs/msg/Imu", "sub", "sensor data, reliable",
              "orientation and gyro"),
        Topic(ODOM_TOPIC, "nav_msgs/msg/Odometry", "pub", description="the estimate"),
        Topic("/tf", "tf2_msgs/msg/TFMessage", "pub",
              description="map → odom from the estimate (the original: a static identity)"),
    )
    WRITES = (ROBOT_POSE,)

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._throttle = WarningThrottle(period=5.0)
        self.estimator = GpsPoseEstimator()
        self._ros: dict[str, Any] = {}
        self._broadcaster = None
        self._reported_rejections = 0
        self._reported_releases = 0
        #: map → odom as last anchored: (the estimator's fixes_taken then, tx, ty, yaw).
        self._anchor: tuple[int, float, float, float] | None = None
        #: The way odometry measured since the anchor's fix: (fixes_taken, x, y of the last
        #: odometry counted, metres so far), for robot_pose's variance.
        self._driven: tuple[int, float, float, float] | None = None
        self._sent_stamp = -math.inf

    def on_initialize(self) -> None:
        self._destroy_ros()
        v = self.params
        with self._lock:
            self.estimator = GpsPoseEstimator(v["initial_pose.x"], v["initial_pose.y"],
                                              gate_speed=v.fix_gate_speed)
            self._reported_rejections = self._reported_releases = 0
            self._anchor, self._sent_stamp, self._driven = None, -math.inf, None
        if self.context.node is not None:
            self._create_ros()

    def on_cleanup(self) -> None:
        self._destroy_ros()

    # -- inputs --------------------------------------------------------------------------------
    def add_fix(self, fix: GNSSPerception) -> None:
        """A GNSS fix (ignored without a fix). Any thread."""
        with self._lock:
            self.estimator.add_fix(fix)

    def add_imu(self, imu: ImuPerception) -> None:
        """An IMU reading. Any thread."""
        if not ((not imu.has_orientation or np.all(np.isfinite(imu.orientation))) and (
                not imu.has_angular_velocity or np.all(np.isfinite(imu.angular_velocity)))):
            self._throttle.warn(self.logger, "imu-nan", f"{self.plugin_name}: non-finite IMU")
            return
        with self._lock:
            self.estimator.add_imu(imu)

    def on_last_known_pose(self, pose: Odometry) -> None:
        """Continue from ``pose``: later fixes are shifted so it holds, and ``map → odom`` is
        anchored on it (at its stamp). The shift compares it with where the estimate put the
        robot at that instant (the last fix moved on by odometry), not with the last fix, so the
        motion in between does not stay in it as a bias."""
        stamp = pose.header.stamp
        with self._lock:
            e = self.estimator
            e.reset(pose.pose.x, pose.pose.y, pose.pose.yaw, self._estimate_at(stamp), stamp)
            odom = self._odometry_at(stamp)
            self._anchor = None if odom is None else (
                self.estimator.fixes_taken, *_anchor_on((pose.pose.x, pose.pose.y, pose.pose.yaw),
                                                        odom, odom[2]))
            self._driven = None if odom is None else (
                self.estimator.fixes_taken, odom[0], odom[1], 0.0)

    def _estimate_at(self, stamp: float) -> tuple[float, float] | None:
        """Where the estimate puts the robot at ``stamp``: the current anchor with odometry
        then, or (a fix taken since the last anchor) that fix moved on by the odometry from its
        stamp; None when odometry does not cover it (an unstamped fix, an outage longer than
        TF's history). Under the lock."""
        e = self.estimator
        now = self._odometry_at(stamp)
        if e.position is None or now is None:
            return None
        if self._anchor is not None and self._anchor[0] == e.fixes_taken:
            return _compose(self._anchor[1:], now)[:2]
        if e.last_fix_stamp <= 0.0:
            return None
        buffer = get_tf_buffer(self.context.namespace)
        tf_info = buffer.get_tf_info()
        try:  # exactly at the fix's stamp: no fallback to the latest
            _, (ox, oy, *_rest) = buffer.lookup_transform_values(
                tf_info.odom_frame, tf_info.robot_footprint_frame, e.last_fix_stamp)
        except LookupError:
            return None
        turn = self._anchor[3] if self._anchor is not None else normalize_angle(e.yaw - now[2])
        c, s = math.cos(turn), math.sin(turn)
        dx, dy = now[0] - ox, now[1] - oy
        return float(e.position[0]) + c * dx - s * dy, float(e.position[1]) + s * dx + c * dy

    # -- cycle ---------------------------------------------------------------------------------
    def update_rt(self, nav_state: NavState) -> None:
        """Nothing (the original's ``update_rt`` is empty)."""

    def update(self, nav_state: NavState) -> None:
        """Broadcast ``map → odom`` from the last fix and IMU reading (once a fix arrived) and
        write ``robot_pose``: that estimate carried on by odometry to the newest
        ``odom → robot`` (:meth:`_carried`), or the fix as it is while ``map → odom`` has no
        anchor on it (no odometry yet, or a fix ahead of odometry waiting for it)."""
        with self._lock:  # the anchor too: a handover between the two would be undone
            e = self.estimator
            if e.position is None:
                self._throttle.warn(self.logger, "no-fix", f"{self.plugin_name}: no GNSS fix yet")
                return
            self._report_gate(e)
            fix = (float(e.position[0]), float(e.position[1]), e.last_fix_stamp, e.yaw,
                   e.imu_stamp, float(e.angular_velocity[2]), e.fixes_taken)
            roll, pitch, yaw, stamp = e.roll, e.pitch, e.yaw, e.stamp
            covariance = e.covariance6()
            angular_velocity = e.angular_velocity.copy()
            # One look at odometry for both: the anchor sent and the pose carried agree.
            latest = self._latest_odometry()
            self._send_map_to_odom(*fix, latest)
            carried = self._carried(fix[6], latest)
        x, y = fix[0], fix[1]
        if carried is not None:
            x, y, stamp, driven = carried
            covariance[:2, :2] += np.eye(2) * (ODOMETRY_DRIFT * driven) ** 2
        qx, qy, qz, qw = _rpy_quaternion(roll, pitch, yaw)
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        odometry = Odometry(
            header=Header(stamp, tf_info.map_frame),
            child_frame_id=tf_info.robot_footprint_frame,
            pose=Pose(x, y, 0.0, qx, qy, qz, qw),
            pose_covariance=covariance,
            twist=Twist(wx=angular_velocity[0], wy=angular_velocity[1], wz=angular_velocity[2]),
        )
        nav_state.set(ROBOT_POSE, odometry)
        publisher = self._ros.get("odom")
        if publisher is not None:
            from easynav.system.ros.converters import odometry_to_msg

            publisher.publish(odometry_to_msg(odometry))

    def _latest_odometry(self) -> tuple[float, tuple[float, ...]] | None:
        """The newest ``odom → robot`` (stamp, (x, y, z, qx, qy, qz, qw)); None, with a
        throttled warning, while TF has none."""
        buffer = get_tf_buffer(self.context.namespace)
        tf_info = buffer.get_tf_info()
        try:
            return buffer.lookup_transform_values(tf_info.odom_frame,
                                                  tf_info.robot_footprint_frame)
        except LookupError as exc:  # no odometry transform (yet): nothing to anchor it on
            self._throttle.warn(self.logger, "no-odom-tf",
                                f"{self.plugin_name}: no map → odom: {exc}")
            return None

    def _carried(self, taken: int, latest: tuple[float, tuple[float, ...]] | None
                 ) -> tuple[float, float, float, float] | None:
        """The robot's position in the map at ``latest``, the newest ``odom → robot``
        (:meth:`_latest_odometry`): ``map → odom`` as anchored on fix number ``taken``
        (:meth:`_send_map_to_odom`, or a handover since) composed with it; that odometry's
        stamp; the way (m) odometry measured since the anchor, summed update by update (a
        drive there and back drifts as much as one on). None when the anchor is not that
        fix's, or without odometry. Under the lock."""
        anchor, driven = self._anchor, self._driven
        if (latest is None or anchor is None or anchor[0] != taken or driven is None
                or driven[0] != taken):
            return None
        newest, (ox, oy, _, *q) = latest
        x, y, _ = _compose(anchor[1:], (ox, oy, quaternion_to_yaw(*q)))
        way = driven[3] + math.hypot(ox - driven[1], oy - driven[2])
        self._driven = (taken, ox, oy, way)
        return x, y, newest, way

    def _report_gate(self, e: GpsPoseEstimator) -> None:
        """Throttled warnings for the fixes the jump gate rejected, and for a far fix taken
        after it rejected enough in a row. Under the lock."""
        if e.rejected_fixes > self._reported_rejections:
            self._reported_rejections = e.rejected_fixes
            self._throttle.warn(self.logger, "jump",
                                f"{self.plugin_name}: a fix jumped away from the estimate: "
                                f"rejected ({e.rejected_fixes} so far; fix_gate_speed "
                                f"{e.gate_speed:g} m/s)")
        if e.released_jumps > self._reported_releases:
            self._reported_releases = e.released_jumps
            self._throttle.warn(self.logger, "release",
                                f"{self.plugin_name}: the fixes stayed away from the estimate "
                                f"for {GATE_RELEASE} in a row: the estimate moves to them")

    def _odometry_at(self, stamp: float) -> tuple[float, float, float] | None:
        """``odom → robot`` (x, y, yaw) at ``stamp`` (the latest when TF has none then; the
        latest for 0), None without odometry."""
        buffer = get_tf_buffer(self.context.namespace)
        tf_info = buffer.get_tf_info()
        try:
            _, (ox, oy, _, *q) = buffer.lookup_transform_values_near(
                tf_info.odom_frame, tf_info.robot_footprint_frame, stamp)
        except LookupError:
            return None
        return ox, oy, quaternion_to_yaw(*q)

    def _send_map_to_odom(self, x: float, y: float, fix_stamp: float, yaw: float,
                          yaw_stamp: float | None, yaw_rate: float, taken: int,
                          latest: tuple[float, tuple[float, ...]] | None) -> None:
        """``map → odom`` that puts the robot at the estimate (nothing while ``latest``, the
        newest ``odom → robot`` from :meth:`_latest_odometry`, is None), anchored once per fix
        taken: the fix's position with ``odom → robot`` at its stamp, the rotation from the IMU
        filter's yaw with odometry's yaw at one instant (the yaw moved back by the gyro to the
        newest odometry when the IMU is ahead of it). Re-sent stamped with the newest
        ``odom → robot``, so that between fixes and through an outage the TF tree's robot
        moves on with odometry from the last fix. A fix ahead of the newest odometry waits for
        it, up to :data:`ODOMETRY_WAIT` (more: another clock, or odometry stalled; anchored on
        the latest odometry, with a warning).

        The original broadcast a static identity, which put the TF tree's robot at the wheel
        odometry's pose: after a few minutes of wheel slip that was metres from
        ``robot_pose``, and what the maps managers fuse into the map frame from the robot's
        sensors landed there (on the campus, walls drawn across the way to a waypoint: no
        path)."""
        if latest is None:  # no odometry transform (yet): nothing to anchor it on
            return
        buffer = get_tf_buffer(self.context.namespace)
        tf_info = buffer.get_tf_info()
        newest = latest[0]
        if newest < self._sent_stamp - CLOCK_JUMP:  # the clock went back: start again
            self._sent_stamp, self._anchor, self._driven = -math.inf, None, None
        ahead = fix_stamp - newest
        if (self._anchor is None or self._anchor[0] != taken) and (
                ahead <= 0.0 or ahead > ODOMETRY_WAIT or fix_stamp <= 0.0):
            if ahead > ODOMETRY_WAIT:
                self._throttle.warn(self.logger, "fix-ahead",
                                    f"{self.plugin_name}: the fix is {ahead:.2f} s ahead of the "
                                    f"newest odometry: map → odom anchored on the latest")
            at = min(fix_stamp, newest) if fix_stamp > 0.0 else newest
            odom = self._odometry_at(at)
            # The IMU's yaw paired with odometry's at one instant: moved back by the gyro when
            # the IMU is a little ahead of odometry; much further ahead (odometry stalled,
            # another clock) the gyro's bias would add up: paired as it is.
            lead = 0.0 if yaw_stamp is None else yaw_stamp - newest
            yaw_at = newest if yaw_stamp is None or lead > 0.0 else yaw_stamp
            yaw_then = yaw - yaw_rate * lead if 0.0 < lead <= ODOMETRY_WAIT else yaw
            odom_yaw = self._odometry_at(yaw_at)
            if odom is None or odom_yaw is None:
                return
            anchor = _anchor_on((x, y, yaw_then), odom, odom_yaw[2])
            if not all(math.isfinite(v) for v in anchor):
                return
            self._anchor = (taken, *anchor)
            self._driven = (taken, odom[0], odom[1], 0.0)
        # Stamped with the newest odometry, never ahead of it: a transform ahead of the rest
        # of the tree (a fix on another clock, odometry stalled, a fix left from before a
        # restart) made every lookup through map fail.
        stamp = newest
        if self._anchor is None or stamp <= self._sent_stamp:
            return  # nothing newer to say (a repeated stamp is TF_REPEATED_DATA for tf2)
        self._sent_stamp = stamp
        _, tx, ty, t_yaw = self._anchor
        transform = TransformStamped(Header(stamp, tf_info.map_frame), tf_info.odom_frame,
                                     Transform(np.array((tx, ty, 0.0)),
                                               np.array(yaw_to_quaternion(t_yaw))))
        if self._broadcaster is not None:
            self._broadcaster.send_transform(transform)
        else:
            buffer.set_transform(transform, self.plugin_name)

    # -- ROS -----------------------------------------------------------------------------------

    def _create_ros(self) -> None:
        from nav_msgs.msg import Odometry as OdometryMsg
        from rclpy.qos import qos_profile_sensor_data
        from sensor_msgs.msg import Imu, NavSatFix

        from easynav.system.sensors.converters.imu import imu_from_msg
        from easynav.system.sensors.converters.nav_sat_fix import gnss_from_msg
        from easynav.system.tf import TFBroadcaster

        node = self.context.node
        qos = qos_profile_sensor_data
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        qos = QoSProfile(history=qos.history, depth=qos.depth,
                         reliability=ReliabilityPolicy.RELIABLE, durability=qos.durability)

        def on_fix(msg):
            try:
                self.add_fix(gnss_from_msg(msg))
            except Exception as exc:  # a callback must not end the executor's spin
                self._throttle.warn(self.logger, "fix", f"{self.plugin_name}: fix dropped: {exc}")

        def on_imu(msg):
            try:
                self.add_imu(imu_from_msg(msg))
            except Exception as exc:
                self._throttle.warn(self.logger, "imu", f"{self.plugin_name}: IMU dropped: {exc}")

        self._ros = {
            "fix": node.create_subscription(NavSatFix, FIX_TOPIC, on_fix, qos),
            "imu": node.create_subscription(Imu, IMU_TOPIC, on_imu, qos),
            "odom": node.create_publisher(OdometryMsg, ODOM_TOPIC, 10),
        }
        self._broadcaster = TFBroadcaster(node,
                                          local_buffer=get_tf_buffer(self.context.namespace))

    def _destroy_ros(self) -> None:
        node = self.context.node
        ros, self._ros = self._ros, {}
        broadcaster, self._broadcaster = self._broadcaster, None
        if node is None:
            return
        for name, entity in ros.items():
            if name == "odom":
                node.destroy_publisher(entity)
            else:
                node.destroy_subscription(entity)
        if broadcaster is not None:
            broadcaster.destroy()
