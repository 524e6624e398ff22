"""GtsamLocalizer without ROS: configuration, GNSS from NavState group gnss, robot_pose with a
marginal covariance, on_last_known_pose."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("gtsam")
pytest.importorskip("pyproj")

from easynav.common.sensors import GNSSPerception, ImuPerception  # noqa: E402
from easynav.common.sensors.gnss_perception import (  # noqa: E402
    COVARIANCE_TYPE_DIAGONAL_KNOWN,
    STATUS_FIX,
)
from easynav.core.nav_state import NavState  # noqa: E402
from easynav.core.plugins import (  # noqa: E402
    DictParameters,
    PluginConfigurationError,
    PluginContext,
)
from easynav.core.types import Header, Odometry, Pose, yaw_to_quaternion  # noqa: E402
from easynav.localizers.fusion.utm_projection import UtmProjection  # noqa: E402
from easynav.localizers.gtsam_localizer import GtsamLocalizer  # noqa: E402

ORIGIN = (40.2834931, -3.8207254, 746.184)


def _plugin(**params):
    values = {"g.latitude_origin": ORIGIN[0], "g.longitude_origin": ORIGIN[1]}
    values.update({f"g.{k}": v for k, v in params.items()})
    plugin = GtsamLocalizer()
    plugin.initialize(PluginContext(parameters=DictParameters(values), namespace="gtsam_t"), "g")
    return plugin


def test_straight_drive_with_gnss_writes_pose_and_covariance():
    projection = UtmProjection(*ORIGIN)
    plugin = _plugin()
    nav_state = NavState()
    rng = np.random.default_rng(0)
    for k in range(1, 201):  # 20 s at 0.5 m/s east, odometry 5 % long
        t = k * 0.1
        plugin.add_odometry(Odometry(header=Header(t, "odom"),
                                     pose=Pose.from_xy_yaw(0.525 * t, 0.0, 0.0)))
        plugin.add_imu(ImuPerception(orientation=np.array(yaw_to_quaternion(0.0)),
                                     orientation_covariance=np.eye(3) * 1e-4, stamp=t))
        if k % 2 == 0:
            lat, lon = projection.inverse(0.5 * t + rng.normal(0, 0.3), rng.normal(0, 0.3))
            nav_state.set("gps", GNSSPerception(
                latitude=lat, longitude=lon, altitude=ORIGIN[2],
                position_covariance=np.eye(3) * 0.09,
                position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN, status=STATUS_FIX,
                stamp=t))
            nav_state.add_to_group("gnss", "gps")
        plugin.update_rt(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    assert math.hypot(pose.pose.x - 10.0, pose.pose.y) < 0.5  # odometry alone: 10.5
    assert 0.0 < pose.pose_covariance[0, 0] < 0.1
    plugin.on_last_known_pose(Odometry(header=Header(20.0, "map"),
                                       pose=Pose.from_xy_yaw(50.0, 5.0, 0.0),
                                       pose_covariance=np.eye(6) * 0.01))
    plugin.update_rt(nav_state)
    pose = nav_state.get("robot_pose", Odometry)
    assert (pose.pose.x, pose.pose.y) == pytest.approx((50.0, 5.0), abs=0.2)


def test_bad_parameters_name_the_culprit():
    with pytest.raises(PluginConfigurationError, match="robust"):
        _plugin(robust="magic")
