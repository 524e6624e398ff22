"""Converters between ROS 2 messages and the native types of ``easynav.core.types``.

This is the only place (with each plugin package's own converters) where ROS messages and native
types meet. Every function is pure and thread-agnostic.
"""

from __future__ import annotations

import math

import numpy as np
from builtin_interfaces.msg import Duration as DurationMsg
from builtin_interfaces.msg import Time as TimeMsg
from diagnostic_msgs.msg import DiagnosticStatus as DiagnosticStatusMsg
from diagnostic_msgs.msg import KeyValue
from geometry_msgs.msg import Pose as PoseMsg
from geometry_msgs.msg import PoseStamped as PoseStampedMsg
from geometry_msgs.msg import TransformStamped as TransformStampedMsg
from geometry_msgs.msg import Twist as TwistMsg
from geometry_msgs.msg import TwistStamped as TwistStampedMsg
from nav_msgs.msg import Goals as GoalsMsg
from nav_msgs.msg import Odometry as OdometryMsg
from nav_msgs.msg import Path as PathMsg
from std_msgs.msg import Header as HeaderMsg

from easynav.core.types import (
    DiagnosticLevel,
    DiagnosticStatus,
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
    Transform,
    TransformStamped,
    Twist,
    TwistStamped,
)

_NS = 1_000_000_000


# -- time -------------------------------------------------------------------------------------
def time_to_msg(seconds: float) -> TimeMsg:
    """Float seconds → builtin_interfaces/Time (negative or non-finite → zero)."""
    if not math.isfinite(seconds) or seconds <= 0.0:
        return TimeMsg()
    ns = round(seconds * _NS)
    return TimeMsg(sec=ns // _NS, nanosec=ns % _NS)


def time_from_msg(msg: TimeMsg) -> float:
    """builtin_interfaces/Time → float seconds."""
    return msg.sec + msg.nanosec * 1e-9


def duration_to_msg(seconds: float) -> DurationMsg:
    """Float seconds → builtin_interfaces/Duration (non-finite → zero)."""
    if not math.isfinite(seconds):
        return DurationMsg()
    ns = round(seconds * _NS)
    return DurationMsg(sec=ns // _NS, nanosec=ns % _NS)


def duration_from_msg(msg: DurationMsg) -> float:
    """builtin_interfaces/Duration → float seconds."""
    return msg.sec + msg.nanosec * 1e-9


# -- header, pose, twist ------------------------------------------------------------------------
def header_to_msg(header: Header) -> HeaderMsg:
    return HeaderMsg(stamp=time_to_msg(header.stamp), frame_id=header.frame_id)


def header_from_msg(msg: HeaderMsg) -> Header:
    return Header(stamp=time_from_msg(msg.stamp), frame_id=msg.frame_id)


def pose_to_msg(pose: Pose) -> PoseMsg:
    msg = PoseMsg()
    p, o = msg.position, msg.orientation
    p.x, p.y, p.z = float(pose.x), float(pose.y), float(pose.z)
    o.x, o.y, o.z, o.w = float(pose.qx), float(pose.qy), float(pose.qz), float(pose.qw)
    return msg


def pose_from_msg(msg: PoseMsg) -> Pose:
    p, o = msg.position, msg.orientation
    return Pose(p.x, p.y, p.z, o.x, o.y, o.z, o.w)


def pose_stamped_to_msg(pose: PoseStamped) -> PoseStampedMsg:
    return PoseStampedMsg(header=header_to_msg(pose.header), pose=pose_to_msg(pose.pose))


def pose_stamped_from_msg(msg: PoseStampedMsg) -> PoseStamped:
    return PoseStamped(header=header_from_msg(msg.header), pose=pose_from_msg(msg.pose))


def twist_to_msg(twist: Twist) -> TwistMsg:
    msg = TwistMsg()
    msg.linear.x, msg.linear.y, msg.linear.z = float(twist.vx), float(twist.vy), float(twist.vz)
    msg.angular.x, msg.angular.y, msg.angular.z = (
        float(twist.wx),
        float(twist.wy),
        float(twist.wz),
    )
    return msg


def twist_from_msg(msg: TwistMsg) -> Twist:
    return Twist(
        msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x, msg.angular.y, msg.angular.z
    )


def twist_stamped_to_msg(twist: TwistStamped) -> TwistStampedMsg:
    return TwistStampedMsg(header=header_to_msg(twist.header), twist=twist_to_msg(twist.twist))


def twist_stamped_from_msg(msg: TwistStampedMsg) -> TwistStamped:
    return TwistStamped(header=header_from_msg(msg.header), twist=twist_from_msg(msg.twist))


# -- odometry, path, goals --------------------------------------------------------------------
def odometry_to_msg(odom: Odometry) -> OdometryMsg:
    msg = OdometryMsg()
    msg.header = header_to_msg(odom.header)
    msg.child_frame_id = odom.child_frame_id
    msg.pose.pose = pose_to_msg(odom.pose)
    msg.pose.covariance = np.asarray(odom.pose_covariance, dtype=float).reshape(36)
    msg.twist.twist = twist_to_msg(odom.twist)
    msg.twist.covariance = np.asarray(odom.twist_covariance, dtype=float).reshape(36)
    return msg


def odometry_from_msg(msg: OdometryMsg) -> Odometry:
    return Odometry(
        header=header_from_msg(msg.header),
        child_frame_id=msg.child_frame_id,
        pose=pose_from_msg(msg.pose.pose),
        pose_covariance=np.array(msg.pose.covariance, dtype=float).reshape(6, 6),
        twist=twist_from_msg(msg.twist.twist),
        twist_covariance=np.array(msg.twist.covariance, dtype=float).reshape(6, 6),
    )


def path_to_msg(path: Path) -> PathMsg:
    msg = PathMsg(header=header_to_msg(path.header))
    msg.poses = [PoseStampedMsg(header=msg.header, pose=pose_to_msg(pose)) for pose in path.poses]
    return msg


def path_from_msg(msg: PathMsg) -> Path:
    return Path(
        header=header_from_msg(msg.header), poses=[pose_from_msg(p.pose) for p in msg.poses]
    )


def goals_to_msg(goals: Goals) -> GoalsMsg:
    return GoalsMsg(
        header=header_to_msg(goals.header), goals=[pose_stamped_to_msg(g) for g in goals.goals]
    )


def goals_from_msg(msg: GoalsMsg) -> Goals:
    return Goals(
        header=header_from_msg(msg.header), goals=[pose_stamped_from_msg(g) for g in msg.goals]
    )


# -- transforms, diagnostics ------------------------------------------------------------------
def transform_stamped_to_msg(ts: TransformStamped) -> TransformStampedMsg:
    msg = TransformStampedMsg()
    msg.header = header_to_msg(ts.header)
    msg.child_frame_id = ts.child_frame_id
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = (float(v) for v in ts.transform.translation)
    r.x, r.y, r.z, r.w = (float(v) for v in ts.transform.rotation)
    return msg


def transform_stamped_from_msg(msg: TransformStampedMsg) -> TransformStamped:
    t, r = msg.transform.translation, msg.transform.rotation
    return TransformStamped(
        header=header_from_msg(msg.header),
        child_frame_id=msg.child_frame_id,
        transform=Transform(np.array((t.x, t.y, t.z)), np.array((r.x, r.y, r.z, r.w))),
    )


def diagnostic_to_msg(status: DiagnosticStatus) -> DiagnosticStatusMsg:
    return DiagnosticStatusMsg(
        level=bytes([int(status.level)]),
        name=status.name,
        message=status.message,
        hardware_id=status.hardware_id,
        values=[KeyValue(key=str(k), value=str(v)) for k, v in status.values.items()],
    )


def diagnostic_from_msg(msg: DiagnosticStatusMsg) -> DiagnosticStatus:
    level = msg.level[0] if isinstance(msg.level, bytes | bytearray) else int(msg.level)
    return DiagnosticStatus(
        level=DiagnosticLevel(level),
        name=msg.name,
        message=msg.message,
        hardware_id=msg.hardware_id,
        values={kv.key: kv.value for kv in msg.values},
    )
