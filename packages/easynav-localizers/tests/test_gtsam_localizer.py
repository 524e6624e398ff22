"""GtsamLocalizer without ROS: configuration, GNSS from NavState group gnss, robot_pose with a
marginal covariance, on_last_known_pose."""

from __future__ import annotations

import functools
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


@functools.cache
def _projection() -> UtmProjection:
    return UtmProjection(*ORIGIN)  # built once: a pyproj transformer takes tens of ms


def _drive_east(plugin, nav_state, t, rng, fix_delay=None):
    """One 0.1 s step of a robot at 0.5 m/s east (odometry 5 % long); with ``fix_delay``, a
    fix (σ 0.3 m) of where it was that long ago."""
    plugin.add_odometry(Odometry(header=Header(t, "odom"),
                                 pose=Pose.from_xy_yaw(0.525 * t, 0.0, 0.0)))
    if fix_delay is not None:
        stamp = t - fix_delay
        lat, lon = _projection().inverse(0.5 * stamp + rng.normal(0, 0.3), rng.normal(0, 0.3))
        nav_state.set("gps", GNSSPerception(
            latitude=lat, longitude=lon, altitude=ORIGIN[2],
            position_covariance=np.eye(3) * 0.09,
            position_covariance_type=COVARIANCE_TYPE_DIAGONAL_KNOWN, status=STATUS_FIX,
            stamp=stamp))
        nav_state.add_to_group("gnss", "gps")


def test_straight_drive_with_gnss_writes_pose_and_covariance():
    plugin = _plugin()
    nav_state = NavState()
    rng = np.random.default_rng(0)
    for k in range(1, 201):  # 20 s, fixes at 5 Hz
        t = k * 0.1
        plugin.add_imu(ImuPerception(orientation=np.array(yaw_to_quaternion(0.0)),
                                     orientation_covariance=np.eye(3) * 1e-4, stamp=t))
        _drive_east(plugin, nav_state, t, rng, fix_delay=0.0 if k % 2 == 0 else None)
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


class _Failing:
    """A smoother whose updates raise (until the recovery replaces it with a new one)."""

    def __init__(self, smoother):
        self._smoother = smoother

    def __getattr__(self, name):
        return getattr(self._smoother, name)

    def update(self, *args):
        raise IndexError("key 'x176' has no clique in the Bayes tree")


def test_a_gnss_driver_late_against_the_odometry_and_a_solver_failure(caplog):
    # The campus matrix row under load: fixes reached NavState ~0.5 s after the odometry of
    # their time; GTSAM's marginalisation broke on the first and raised every cycle after.
    caplog.set_level("WARNING", logger="easynav")
    plugin = _plugin()
    nav_state = NavState()
    rng = np.random.default_rng(1)
    for k in range(1, 401):  # 40 s, fixes at 5 Hz, 0.5 s late
        t = k * 0.1
        _drive_east(plugin, nav_state, t, rng, fix_delay=0.5 if k % 2 == 0 and k > 5 else None)
        if k == 200:  # and GTSAM raising once more, whatever the cause
            plugin.estimator._smoother = _Failing(plugin.estimator._smoother)
        plugin.update_rt(nav_state)
        if k >= 20:
            pose = nav_state.get("robot_pose", Odometry)
            assert math.hypot(pose.pose.x - 0.5 * t, pose.pose.y) < 0.6, t
    assert plugin.estimator.gnss_used > 150 and plugin.estimator.solver_failures == 1
    warnings = [r.getMessage() for r in caplog.records if "GTSAM failed" in r.getMessage()]
    assert len(warnings) == 1 and "no clique" in warnings[0]


def test_bad_parameters_name_the_culprit():
    with pytest.raises(PluginConfigurationError, match="robust"):
        _plugin(robust="magic")
    with pytest.raises(PluginConfigurationError, match=r"g\.lag: .*keyframe periods"):
        _plugin(lag=0.3, keyframe_period=0.2)
