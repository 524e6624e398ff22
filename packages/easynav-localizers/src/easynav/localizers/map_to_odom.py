"""map_to_odom: the ``map → odom`` transform that puts the robot at a global estimate."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from easynav.common.tf import TFBuffer
from easynav.core.types import (
    Header,
    Transform,
    TransformStamped,
    normalize_angle,
    quaternion_to_yaw,
    yaw_to_quaternion,
)

#: The longest time (s) :func:`carry_pose` moves a pose at constant velocity, where odometry
#: does not tell the motion.
MAX_TWIST_EXTRAPOLATION = 1.0


def map_to_odom(buffer: TFBuffer, x: float, y: float, yaw: float, stamp: float,
                twist: Sequence[float] | None = None) -> TransformStamped:
    """``map → odom`` such that ``map → odom → robot`` is the planar estimate ``(x, y, yaw)``
    at ``stamp``, with ``odom → robot`` looked up at ``stamp``, as robot_localization does.
    With the latest transform instead, an estimate that lags its inputs (queued odometry on a
    loaded machine) puts ``map → odom`` off by the distance driven in between.

    When ``stamp`` is outside the buffer's window (typically newer than the last ``odom →
    robot`` received: the transforms come through the TF listener, the estimator's inputs
    through their own subscriptions, and either can lag under load) the latest transform is
    used, and the estimate is first moved to that transform's stamp with ``twist`` — the
    estimate's body-frame velocity ``(vx, vy, vyaw)``, held constant over the gap — so that
    both sides of the composition describe the same instant. Without it (``None``) the
    estimate is used as it is: a pose estimated 0.4 s after the transform at 0.7 m/s put the
    robot 0.28 m ahead of itself until the next update.

    The transform is stamped ``stamp``. Frames from the buffer's TFInfo. Raises the buffer's
    lookup errors (TransformError) when there is no ``odom → robot`` transform yet. Pure
    computation on the buffer; any thread.
    """
    tf_info = buffer.get_tf_info()
    odom_stamp, (ox, oy, _, qx, qy, qz, qw) = buffer.lookup_transform_values_near(
        tf_info.odom_frame, tf_info.robot_footprint_frame, stamp)
    if twist is not None and odom_stamp != 0.0 and odom_stamp != stamp:
        x, y, yaw = _move(x, y, yaw, twist, odom_stamp - stamp)
    t_yaw = normalize_angle(yaw - quaternion_to_yaw(qx, qy, qz, qw))
    c, s = math.cos(t_yaw), math.sin(t_yaw)
    return TransformStamped(
        Header(stamp, tf_info.map_frame), tf_info.odom_frame,
        Transform(np.array((x - (c * ox - s * oy), y - (s * ox + c * oy), 0.0)),
                  np.array(yaw_to_quaternion(t_yaw))),
    )


def _move(x: float, y: float, yaw: float, twist: Sequence[float],
          dt: float) -> tuple[float, float, float]:
    """The pose ``dt`` seconds later (earlier when negative) at constant body velocity
    ``(vx, vy, vyaw)``: the rotation taken at the middle of the interval (second order)."""
    vx, vy, vyaw = (float(v) for v in twist)
    mid = yaw + 0.5 * vyaw * dt
    c, s = math.cos(mid), math.sin(mid)
    return x + (c * vx - s * vy) * dt, y + (s * vx + c * vy) * dt, yaw + vyaw * dt


def carry_pose(buffer: TFBuffer, x: float, y: float, yaw: float, stamp: float, until: float,
               twist: Sequence[float] | None = None) -> tuple[float, float, float]:
    """The planar pose ``(x, y, yaw)`` the robot had at ``stamp``, carried to ``until`` by the
    robot's motion in between, as the ``odom → robot`` transforms record it: the pose at
    ``stamp`` fixes ``map → odom`` (:func:`map_to_odom`), and ``odom → robot`` at ``until``
    puts the robot on it.

    A localizer that takes over from another gets the last pose its predecessor wrote, stamped
    when that one last ran; the reconfiguration between them takes a second or more, and the
    robot may drive on. Taken as it is, the pose put the new estimate behind the robot by that
    distance (0.25 m at 0.27 m/s) for the rest of a mission on odometry alone.

    Without an ``odom → robot`` transform (a robot that gives none, or no history back to
    ``stamp``) the pose is moved at constant body velocity ``twist`` ``(vx, vy, vyaw)``, for
    :data:`MAX_TWIST_EXTRAPOLATION` at most (the robot may have braked meanwhile), and kept as
    it is when ``twist`` is None. A ``stamp`` of 0 (unstamped, as an ``initialpose``
    may be) means "now": the pose is returned unchanged. Pure computation on the buffer; any
    thread.
    """
    if stamp <= 0.0 or until <= stamp:
        return x, y, yaw
    tf_info = buffer.get_tf_info()
    try:
        # Without its own stamp in the window, map → odom would be anchored on the wrong
        # transform: then the motion is not known from odometry.
        if buffer.lookup_transform_values_near(
                tf_info.odom_frame, tf_info.robot_footprint_frame, stamp)[0] != stamp:
            raise LookupError(stamp)
        anchor = map_to_odom(buffer, x, y, yaw, stamp).transform
        odom_stamp, (ox, oy, _, qx, qy, qz, qw) = buffer.lookup_transform_values_near(
            tf_info.odom_frame, tf_info.robot_footprint_frame, until)
    except LookupError:
        return (x, y, yaw) if twist is None else _move(
            x, y, yaw, twist, min(until - stamp, MAX_TWIST_EXTRAPOLATION))
    m_yaw = quaternion_to_yaw(*anchor.rotation)
    c, s = math.cos(m_yaw), math.sin(m_yaw)
    mx, my = float(anchor.translation[0]), float(anchor.translation[1])
    x, y = mx + c * ox - s * oy, my + s * ox + c * oy
    yaw = normalize_angle(m_yaw + quaternion_to_yaw(qx, qy, qz, qw))
    if twist is not None and odom_stamp != until:  # odometry ends before ``until``
        x, y, yaw = _move(x, y, yaw, twist, min(until - odom_stamp, MAX_TWIST_EXTRAPOLATION))
    return x, y, yaw
