"""The playground's outdoor sensors (IMU, GNSS) and the campus world, without ROS."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

pytest.importorskip("pyproj")

from easynav.localizers.fusion.utm_projection import UtmProjection  # noqa: E402
from easynav.playground.sim import GnssReceiver, ImuSensor  # noqa: E402
from easynav.playground.world_description import (  # noqa: E402
    WORLDS_DIR,
    WorldDescription,
    load_waypoints,
)

ORIGIN = (40.2834931, -3.8207254, 746.184)


def test_imu_gyro_bias_noise_and_gravity():
    imu = ImuSensor(rate=50.0, gyro_noise=0.01, gyro_bias=0.003, accel_noise=0.02,
                    yaw_noise=0.02, rng=np.random.default_rng(0))
    readings = [imu.sample(k * 0.02, 0.5, 1.0, 0.2) for k in range(2000)]
    wz = np.array([r.angular_velocity[2] for r in readings])
    az = np.array([r.linear_acceleration[2] for r in readings])
    ay = np.array([r.linear_acceleration[1] for r in readings])
    yaw = np.array([r.yaw for r in readings])
    assert wz.mean() == pytest.approx(0.203, abs=0.002)
    assert wz.std() == pytest.approx(0.01, rel=0.1)
    assert az.mean() == pytest.approx(9.80665, abs=0.005)  # gravity on z
    assert ay.mean() == pytest.approx(0.2, abs=0.005)  # centripetal v·ω
    assert yaw.mean() == pytest.approx(0.5, abs=0.005)
    with pytest.raises(ValueError, match="rate"):
        ImuSensor(rate=0.0)


def test_gnss_noise_outage_and_jumps_in_metres():
    projection = UtmProjection(*ORIGIN)
    gnss = GnssReceiver(ORIGIN, rate=5.0, noise=0.3, outages=[[10.0, 20.0]],
                        rng=np.random.default_rng(1))
    fixes = [gnss.fix(k * 0.2, 12.0, -7.0) for k in range(200)]
    good = [f for f in fixes if f.status == 0]
    assert len(good) == 150  # 50 fixes (10 s at 5 Hz) lost in the outage
    assert all(math.isnan(f.latitude) for f in fixes if f.status < 0)
    xy = np.array([projection.forward(f.latitude, f.longitude) for f in good])
    assert xy.mean(axis=0) == pytest.approx((12.0, -7.0), abs=0.08)
    assert xy.std(axis=0) == pytest.approx((0.3, 0.3), rel=0.2)
    jumper = GnssReceiver(ORIGIN, noise=0.0, jump_probability=1.0, jump_distance=30.0,
                          rng=np.random.default_rng(2))
    fix = jumper.fix(1.0, 0.0, 0.0)
    assert fix.jump
    assert math.hypot(*projection.forward(fix.latitude, fix.longitude)) == pytest.approx(30.0,
                                                                                          abs=0.01)
    with pytest.raises(ValueError, match="rate"):
        GnssReceiver(ORIGIN, rate=20.0)


def test_campus_world_has_origin_sensors_and_latlon_waypoints():
    world = WorldDescription.resolve("campus")
    assert world.geodetic_origin == ORIGIN
    defaults = world.sensor_parameter_defaults()
    assert defaults["imu.enabled"] and defaults["gnss.enabled"]
    assert defaults["gnss.outages"] == [40.0, 55.0]
    waypoints = load_waypoints(world.waypoints_path)
    latlon = yaml.safe_load(world.waypoints_path.read_text())["latlon"]
    projection = UtmProjection(*ORIGIN)
    for (x, y, yaw), (lat, lon, yaw2) in zip(waypoints, latlon, strict=True):
        assert projection.forward(lat, lon) == pytest.approx((x, y), abs=0.01)
        assert yaw == yaw2
        assert world.world.distance_to_occupied(x, y, 2.0) >= 1.0  # room for the robot
    assert (WORLDS_DIR / "maps" / "campus.pgm").is_file()


def test_world_sensor_sections_are_checked(tmp_path):
    (tmp_path / "w.map").write_text("2 2 1.0 0.0 0.0\n0 0 0 0\n")
    (tmp_path / "w.yaml").write_text("map: w.map\ngnss: {rate: 5.0}\n")
    with pytest.raises(ValueError, match="geodetic_origin"):
        WorldDescription.from_description_file(tmp_path / "w.yaml")
    (tmp_path / "w.yaml").write_text("map: w.map\nimu: {rtae: 5.0}\n")
    with pytest.raises(ValueError, match="imu"):
        WorldDescription.from_description_file(tmp_path / "w.yaml")
