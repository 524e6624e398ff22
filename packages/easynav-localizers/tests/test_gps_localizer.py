"""GpsLocalizer without ROS: UTM positions, initial pose, covariance, the fed-back yaw."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("pyproj")

from easynav.common.sensors import GNSSPerception, ImuPerception  # noqa: E402
from easynav.common.sensors.gnss_perception import (  # noqa: E402
    COVARIANCE_TYPE_DIAGONAL_KNOWN,
    STATUS_FIX,
    STATUS_NO_FIX,
)
from easynav.core.nav_state import NavState  # noqa: E402
from easynav.core.plugins import DictParameters, PluginContext  # noqa: E402
from easynav.core.types import Odometry, yaw_to_quaternion  # noqa: E402
from easynav.localizers.fusion.utm_projection import UtmProjection  # noqa: E402
from easynav.localizers.gps_localizer import GpsLocalizer  # noqa: E402

ORIGIN = (40.2834931, -3.8207254)


def _fix(projection, x, y, stamp, sigma=0.5):
    lat, lon = projection.inverse(x, y)
    return GNSSPerception(latitude=lat, longitude=lon, altitude=700.0,
                          position_covariance=np.eye(3) * sigma**2,
                          position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN,
                          status=STATUS_FIX, stamp=stamp)


def _plugin(params=None, namespace="gps_test"):
    plugin = GpsLocalizer()
    values = {f"gps.{k}": v for k, v in (params or {}).items()}
    plugin.initialize(PluginContext(parameters=DictParameters(values), namespace=namespace),
                      "gps")
    return plugin


def test_positions_relative_to_first_fix_with_covariance():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin()
    nav_state = NavState()
    plugin.update(nav_state)
    assert not nav_state.has("robot_pose")  # no fix yet
    plugin.add_fix(_fix(projection, 10.0, 20.0, 1.0))
    plugin.add_fix(GNSSPerception(status=STATUS_NO_FIX, stamp=1.5))  # ignored
    plugin.add_fix(_fix(projection, 13.0, 24.0, 2.0))
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    assert (pose.pose.x, pose.pose.y) == pytest.approx((3.0, 4.0), abs=1e-3)
    assert pose.pose_covariance[0, 0] == pytest.approx(0.25)
    assert pose.header.stamp == 2.0


def test_initial_pose_places_the_first_fix():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin({"initial_pose.x": 5.0, "initial_pose.y": -2.0}, "gps_test_init")
    plugin.add_fix(_fix(projection, 100.0, 100.0, 1.0))
    plugin.add_fix(_fix(projection, 101.0, 100.0, 2.0))
    nav_state = NavState()
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry).pose
    assert (pose.x, pose.y) == pytest.approx((6.0, -2.0), abs=1e-3)


def _imu(yaw, wz, stamp):
    return ImuPerception(orientation=np.array(yaw_to_quaternion(yaw)),
                         orientation_covariance=np.eye(3) * 0.05**2,
                         angular_velocity=np.array((0.0, 0.0, wz)),
                         angular_velocity_covariance=np.eye(3) * 0.01**2, stamp=stamp)


def test_filtered_yaw_is_fed_back_so_gyro_bias_does_not_drift():
    # The robot stands still; the gyro reads a 0.05 rad/s bias. Integrating the raw gyro (the
    # original) drifts 5 rad in 100 s; the fed-back filter stays near the IMU's yaw.
    plugin = _plugin(namespace="gps_test_yaw")
    for k in range(2001):
        plugin.add_imu(_imu(0.5, 0.05, k * 0.05))
    yaw = plugin.estimator.yaw
    # Steady state of yaw = 0.99 (yaw + b dt) + 0.01 y: 0.99 b dt / 0.01 above the IMU yaw.
    assert yaw == pytest.approx(0.5 + 0.99 * 0.05 * 0.05 / 0.01, abs=0.01)
    assert 0.0 < plugin.estimator.yaw_variance < 0.05**2


def test_last_known_pose_moves_the_estimate():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin(namespace="gps_test_reset")
    plugin.add_fix(_fix(projection, 0.0, 0.0, 1.0))
    from easynav.core.types import Header, Pose

    plugin.on_last_known_pose(Odometry(header=Header(1.0, "map"),
                                       pose=Pose.from_xy_yaw(7.0, 8.0, 1.0)))
    plugin.add_fix(_fix(projection, 1.0, 0.0, 2.0))
    nav_state = NavState()
    plugin.update(nav_state)
    pose = nav_state.get("robot_pose", Odometry).pose
    assert (pose.x, pose.y) == pytest.approx((8.0, 8.0), abs=1e-3)
    assert pose.yaw == pytest.approx(1.0)
    assert math.isfinite(pose.x)
