"""ROS sensor messages -> perception data: every converter against a direct computation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sensor_test_helpers import (
    make_cloud,
    make_detections,
    make_fix,
    make_image,
    make_imu,
    make_odometry,
    make_scan,
)

from easynav.system.sensors import PerceptionConversionError
from easynav.system.sensors.converters import (
    LaserScanConverter,
    detections_from_msg,
    gnss_from_msg,
    image_from_msg,
    imu_from_msg,
    point_cloud2_from_points,
    points_from_point_cloud2,
)
from easynav.system.sensors.handlers import (
    ImageHandler,
    LaserScanHandler,
    OdometryHandler,
    PointCloud2Handler,
)


# -- LaserScan ---------------------------------------------------------------------------------
def test_scan_to_points_matches_polar_to_cartesian():
    rng = np.random.default_rng(1)
    ranges = rng.uniform(0.2, 9.0, 360).astype(np.float32)
    msg = make_scan(ranges, angle_min=-3.0, angle_increment=0.0167)
    points, stats = LaserScanConverter().convert(msg)
    angles = -3.0 + 0.0167 * np.arange(360)
    r = ranges.astype(np.float64)
    expected = np.column_stack((r * np.cos(angles), r * np.sin(angles), np.zeros(360)))
    np.testing.assert_allclose(points, expected, atol=1e-6)
    assert points.dtype == np.float64 and points.shape == (360, 3)
    assert stats.dropped == 0 and stats.beams == 360


def test_scan_drops_nan_inf_and_out_of_range_and_counts_them():
    ranges = [1.0, math.nan, math.inf, -math.inf, 0.05, 10.5, 2.0, 10.0, 0.1]
    msg = make_scan(ranges, angle_min=0.0, angle_increment=0.1, range_min=0.1, range_max=10.0)
    points, stats = LaserScanConverter().convert(msg)
    assert (stats.not_finite, stats.out_of_range, stats.dropped) == (3, 2, 5)
    assert (stats.infinite, stats.invalid) == (2, 3)  # ±inf are REP 117 values, not errors
    kept = np.array([0, 6, 7, 8])
    r = np.array([1.0, 2.0, 10.0, 0.1])
    np.testing.assert_allclose(points[:, 0], r * np.cos(0.1 * kept), atol=1e-6)
    np.testing.assert_allclose(points[:, 1], r * np.sin(0.1 * kept), atol=1e-6)
    assert np.all(np.isfinite(points))


def test_scan_geometry_change_recomputes_the_beam_table():
    converter = LaserScanConverter()
    converter.convert(make_scan([1.0] * 10, angle_min=0.0, angle_increment=0.1))
    points, _ = converter.convert(make_scan([1.0] * 5, angle_min=1.0, angle_increment=0.2))
    np.testing.assert_allclose(points[:, 0], np.cos(1.0 + 0.2 * np.arange(5)), atol=1e-6)


def test_scan_with_broken_geometry_is_rejected():
    with pytest.raises(PerceptionConversionError, match="not finite"):
        LaserScanConverter().convert(make_scan([1.0], angle_increment=math.nan))
    with pytest.raises(PerceptionConversionError, match="range_min"):
        LaserScanConverter().convert(make_scan([1.0], range_min=5.0, range_max=1.0))


def test_empty_scan_gives_no_points():
    points, stats = LaserScanConverter().convert(make_scan([]))
    assert points.shape == (0, 3) and stats.beams == 0


def test_laser_handler_warns_naming_the_sensor_and_makes_read_only_points(caplog):
    handler = LaserScanHandler()
    msg = make_scan([1.0, math.nan, 50.0], frame="front_laser", stamp=12.5)
    perception = handler.to_perception(msg, "laser1")
    assert perception.frame_id == "front_laser" and perception.stamp == 12.5
    assert len(perception) == 1 and not perception.points.flags.writeable
    assert "Sensor 'laser1'" in caplog.text and "dropped 2 of 3 ranges" in caplog.text
    assert handler.dropped_total == 2


def test_laser_handler_drops_rep117_no_returns_without_a_warning(caplog):
    """+inf (nothing within range) and -inf (too close) are what a conforming driver publishes
    in an open space: dropped, counted, and no warning every 10 s."""
    handler = LaserScanHandler()
    perception = handler.to_perception(make_scan([1.0, math.inf, -math.inf, 2.0]), "laser1")
    assert len(perception) == 2 and handler.dropped_total == 2
    assert "dropped" not in caplog.text


# -- PointCloud2 --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "dtype, offsets, big_endian",
    [
        ("f4", (0, 4, 8), False),
        ("f8", (0, 8, 16), False),
        ("f4", (8, 0, 4), False),  # fields in another order
        ("f4", (4, 12, 20), True),  # gaps between fields, big endian
        ("f8", (16, 0, 8), True),
    ],
)
def test_cloud_fields_at_any_offset_type_and_byte_order(dtype, offsets, big_endian):
    rng = np.random.default_rng(2)
    pts = rng.uniform(-20, 20, (257, 3))
    msg = make_cloud(pts, dtype=dtype, offsets=offsets, big_endian=big_endian)
    got, dropped = points_from_point_cloud2(msg)
    expected = pts.astype(dtype).astype(np.float64)
    np.testing.assert_array_equal(got, expected)
    assert dropped == 0 and got.dtype == np.float64


def test_organised_cloud_with_row_padding():
    pts = np.arange(60, dtype=np.float64).reshape(20, 3)
    msg = make_cloud(pts, height=4, row_padding=6)
    got, _ = points_from_point_cloud2(msg)
    np.testing.assert_array_equal(got, pts)


def test_cloud_rows_with_nan_or_inf_are_dropped_and_counted():
    pts = np.array([[1, 2, 3], [math.nan, 0, 0], [0, math.inf, 0], [4, 5, 6], [0, 0, -math.inf]])
    for dtype in ("f4", "f8"):
        got, dropped = points_from_point_cloud2(make_cloud(pts, dtype=dtype, offsets=(0, 8, 16)))
        np.testing.assert_array_equal(got, [[1, 2, 3], [4, 5, 6]])
        assert dropped == 3


def test_empty_cloud_gives_no_points():
    got, dropped = points_from_point_cloud2(make_cloud(np.empty((0, 3))))
    assert got.shape == (0, 3) and dropped == 0


@pytest.mark.parametrize(
    "breakage, message",
    [
        (lambda m: setattr(m, "fields", [f for f in m.fields if f.name != "z"]), "no field z"),
        (lambda m: setattr(m.fields[1], "datatype", 5), "datatype INT32"),
        (lambda m: setattr(m, "point_step", 8), "does not fit in point_step"),
        (lambda m: setattr(m, "data", bytes(m.data)[:-5]), "bytes"),
        (lambda m: setattr(m, "row_step", 10), "row_step 10 is shorter"),
    ],
)
def test_malformed_clouds_raise_a_conversion_error_saying_what_is_wrong(breakage, message):
    msg = make_cloud(np.ones((10, 3)))
    breakage(msg)
    with pytest.raises(PerceptionConversionError, match=message):
        points_from_point_cloud2(msg)


def test_fused_cloud_message_round_trips():
    pts = np.random.default_rng(3).uniform(-5, 5, (100, 3))
    msg = point_cloud2_from_points(pts, "base_footprint", 12.25)
    assert msg.header.frame_id == "base_footprint"
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12, 250_000_000)
    got, _ = points_from_point_cloud2(msg)
    np.testing.assert_allclose(got, pts, atol=1e-5)


def test_cloud_handler_keeps_stamp_and_frame():
    perception = PointCloud2Handler().to_perception(make_cloud([[1, 2, 3]], stamp=4.5), "c")
    assert perception.frame_id == "lidar" and perception.stamp == 4.5
    assert not perception.points.flags.writeable


# -- Image --------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "encoding, dtype, channels",
    [("rgb8", np.uint8, 3), ("bgra8", np.uint8, 4), ("mono8", np.uint8, 1),
     ("mono16", np.uint16, 1), ("16UC1", np.uint16, 1), ("32FC1", np.float32, 1),
     ("8UC3", np.uint8, 3), ("64FC1", np.float64, 1)],
)  # fmt: skip
def test_image_encodings_become_hwc_arrays(encoding, dtype, channels):
    rng = np.random.default_rng(4)
    array = (rng.uniform(0, 200, (5, 7, channels))).astype(dtype)
    for big_endian in (False, True):
        for padding in (0, 3):
            msg = make_image(array, encoding, big_endian=big_endian, row_padding=padding)
            got = image_from_msg(msg)
            np.testing.assert_array_equal(got, array)
            assert got.dtype == np.dtype(dtype) and not got.flags.writeable


def test_image_handler_and_bad_images():
    perception = ImageHandler().to_perception(
        make_image(np.zeros((2, 3, 3), np.uint8), "rgb8"), "c"
    )
    assert (perception.height, perception.width, perception.encoding) == (2, 3, "rgb8")
    with pytest.raises(PerceptionConversionError, match="encoding 'jpeg' is not supported"):
        image_from_msg(make_image(np.zeros((2, 3), np.uint8), "jpeg"))
    short = make_image(np.zeros((4, 4, 3), np.uint8), "rgb8")
    short.data = bytes(short.data)[:20]
    with pytest.raises(PerceptionConversionError, match="20 bytes"):
        image_from_msg(short)
    narrow = make_image(np.zeros((4, 4, 3), np.uint8), "rgb8")
    narrow.step = 5
    with pytest.raises(PerceptionConversionError, match="step 5 is shorter"):
        image_from_msg(narrow)


# -- Imu, NavSatFix, Odometry, Detection3DArray ------------------------------------------------
def test_imu_fields_and_not_measured_quantities():
    imu = imu_from_msg(make_imu(stamp=3.0, yaw=0.4))
    np.testing.assert_allclose(imu.orientation, (0, 0, math.sin(0.2), math.cos(0.2)))
    np.testing.assert_allclose(imu.angular_velocity, (0, 0, 0.5))
    np.testing.assert_allclose(imu.linear_acceleration, (0, 0, 9.81))
    assert imu.angular_velocity_covariance[2, 2] == 0.02 and imu.stamp == 3.0
    assert imu.has_orientation
    no_orientation = make_imu(orientation_known=False)
    no_orientation.orientation.x = math.nan  # allowed: marked as not measured
    assert not imu_from_msg(no_orientation).has_orientation
    broken = make_imu(gyro=(0.0, math.nan, 0.0))
    with pytest.raises(PerceptionConversionError, match="angular_velocity is not finite"):
        imu_from_msg(broken)


def test_gnss_fix_and_no_fix():
    gnss = gnss_from_msg(make_fix(stamp=5.0))
    assert (gnss.latitude, gnss.longitude, gnss.altitude) == (40.28, -3.82, 650.0)
    assert gnss.has_fix and gnss.position_covariance[2, 2] == 4.0
    assert gnss.position_covariance_type == 2 and gnss.service == 1
    no_fix = gnss_from_msg(make_fix(lat=math.nan, lon=math.nan, status=-1))
    assert not no_fix.has_fix
    with pytest.raises(PerceptionConversionError, match="a fix"):
        gnss_from_msg(make_fix(lat=math.nan, status=0))


def test_odometry_handler():
    perception = OdometryHandler().to_perception(make_odometry(stamp=7.0), "odom")
    assert perception.frame_id == "odom" and perception.stamp == 7.0
    odom = perception.odometry
    assert odom.child_frame_id == "base_footprint"
    assert (odom.pose.x, odom.pose.y) == (1.0, 2.0)
    assert odom.pose.yaw == pytest.approx(0.5) and odom.twist.vx == pytest.approx(0.3)
    with pytest.raises(PerceptionConversionError, match="not finite"):
        OdometryHandler().to_perception(make_odometry(x=math.inf), "odom")


def test_detections_take_the_best_hypothesis_and_skip_broken_boxes():
    msg = make_detections(
        [
            ("a", [("chair", 0.4), ("person", 0.9)], (1.0, 2.0, 0.5), (0.5, 0.5, 1.8)),
            ("b", [], (3.0, 0.0, 0.0), (1.0, 1.0, 1.0)),
            ("c", [("box", 0.7)], (math.nan, 0.0, 0.0), (1.0, 1.0, 1.0)),
        ]
    )
    detections, problems = detections_from_msg(msg)
    assert [d.id for d in detections] == ["a", "b"]
    assert detections[0].class_id == "person" and detections[0].score == pytest.approx(0.9)
    assert (detections[0].center.x, detections[0].center.y) == (1.0, 2.0)
    np.testing.assert_allclose(detections[0].size, (0.5, 0.5, 1.8))
    assert detections[1].class_id == "" and detections[1].score == 0.0
    assert len(problems) == 1 and "id 'c'" in problems[0]
