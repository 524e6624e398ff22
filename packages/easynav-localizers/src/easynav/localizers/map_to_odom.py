"""map_to_odom: the ``map → odom`` transform that puts the robot at a global estimate."""

from __future__ import annotations

import math
from collections import deque
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


class PoseHistory:
    """The recent planar estimates ``(stamp, x, y, yaw)`` of a localizer, oldest first, so
    that :func:`map_to_odom` can take the estimate at the time of the newest ``odom → robot``
    transform instead of moving the newest estimate there by its velocity.

    Under load the TF listener's queue (depth 100) lags the localizer's own odometry
    subscription by up to a second; moved across that gap by the filter's noisy velocity
    estimate, ``map → odom`` jumped by up to 0.2 m between consecutive updates.

    Thread contract: one owner thread (not locked).
    """

    def __init__(self, span: float = 3.0) -> None:
        self.span = span
        self._samples: deque[tuple[float, float, float, float]] = deque()

    def add(self, stamp: float, x: float, y: float, yaw: float) -> None:
        """Append an estimate (an older or equal stamp than the last one is ignored)."""
        samples = self._samples
        if samples and stamp <= samples[-1][0]:
            return
        samples.append((float(stamp), float(x), float(y), float(yaw)))
        while samples and samples[0][0] < stamp - self.span:
            samples.popleft()

    def clear(self) -> None:
        """Forget every estimate (the localizer jumped: its earlier ones no longer hold)."""
        self._samples.clear()

    def at(self, stamp: float) -> tuple[float, float, float] | None:
        """The estimate at ``stamp``, interpolated (yaw along the shorter arc); None outside
        the span held."""
        samples = self._samples
        if not samples or not samples[0][0] <= stamp <= samples[-1][0]:
            return None
        hi = next(i for i, sample in enumerate(samples) if sample[0] >= stamp)
        t1, x1, y1, yaw1 = samples[hi]
        if t1 == stamp or hi == 0:
            return x1, y1, yaw1
        t0, x0, y0, yaw0 = samples[hi - 1]
        f = (stamp - t0) / (t1 - t0)
        return (x0 + f * (x1 - x0), y0 + f * (y1 - y0),
                normalize_angle(yaw0 + f * normalize_angle(yaw1 - yaw0)))


def map_to_odom(buffer: TFBuffer, x: float, y: float, yaw: float, stamp: float,
                twist: Sequence[float] | None = None,
                history: PoseHistory | None = None) -> TransformStamped:
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

    With a ``history`` that holds the estimate at that transform's stamp, that estimate is
    used instead of moving the newest one (exact where the velocity is noisy).

    The transform is stamped ``stamp``. Frames from the buffer's TFInfo. Raises the buffer's
    lookup errors (TransformError) when there is no ``odom → robot`` transform yet. Pure
    computation on the buffer; any thread.
    """
    tf_info = buffer.get_tf_info()
    odom_stamp, (ox, oy, _, qx, qy, qz, qw) = buffer.lookup_transform_values_near(
        tf_info.odom_frame, tf_info.robot_footprint_frame, stamp)
    then = history.at(odom_stamp) if (
        history is not None and odom_stamp != 0.0 and odom_stamp != stamp) else None
    if then is not None:
        x, y, yaw = then
    elif twist is not None and odom_stamp != 0.0 and odom_stamp != stamp:
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
