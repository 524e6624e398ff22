"""PointPerceptionsOps: every operation against a direct numpy computation."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from easynav.common.sensors import PointPerception, PointPerceptionsOps, voxel_downsample
from easynav.common.tf import TFBuffer

NAN = math.nan


def perception(points, frame="laser", stamp=10.0, valid=True):
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    pts.flags.writeable = False
    return PointPerception(points=pts, frame_id=frame, stamp=stamp, valid=valid)


def cloud(n=500, seed=0, scale=5.0):
    return np.random.default_rng(seed).uniform(-scale, scale, (n, 3))


def reference_voxel_first(points, resolution):
    """First point of every voxel, in input order: a plain Python loop."""
    seen = set()
    keep = []
    for i, p in enumerate(points):
        key = tuple(int(v) for v in np.floor(p / resolution))
        if key not in seen:
            seen.add(key)
            keep.append(i)
    return points[keep]


def tf_tree():
    """base_footprint <- laser: 0.3 m ahead, 0.2 m up, yawed 90°; odom -> base_footprint moving."""
    buffer = TFBuffer()
    q = Rotation.from_euler("z", math.pi / 2).as_quat()
    buffer.set_transform_values("base_footprint", "laser", 0.0, (0.3, 0.0, 0.2, *q), "t", True)
    buffer.set_transform_values("odom", "base_footprint", 9.0, (1.0, 0, 0, 0, 0, 0, 1), "t")
    buffer.set_transform_values("odom", "base_footprint", 11.0, (3.0, 0, 0, 0, 0, 0, 1), "t")
    return buffer


def laser_to_base(points):
    rot = Rotation.from_euler("z", math.pi / 2).as_matrix()
    return points @ rot.T + (0.3, 0.0, 0.2)


# -- filter ------------------------------------------------------------------------------------
def test_filter_keeps_points_inside_bounds_with_nan_as_unbounded():
    pts = cloud()
    got = PointPerceptionsOps([perception(pts)]).filter((-1, NAN, 0.0), (2, 3, NAN)).as_points()
    mask = (pts[:, 0] >= -1) & (pts[:, 0] <= 2) & (pts[:, 1] <= 3) & (pts[:, 2] >= 0.0)
    np.testing.assert_array_equal(got, pts[mask])


def test_filter_all_nan_is_a_no_op_and_wrong_length_is_an_error():
    pts = cloud(50)
    np.testing.assert_array_equal(
        PointPerceptionsOps([perception(pts)]).filter((NAN,) * 3, (NAN,) * 3).as_points(), pts
    )
    with pytest.raises(ValueError, match="min_xyz must have 3 values"):
        PointPerceptionsOps([perception(pts)]).filter((0, 0), (1, 1, 1))


def test_filter_after_fuse_applies_in_the_fused_frame():
    pts = cloud(400)
    ops = PointPerceptionsOps({"laser1": perception(pts)}, tf_buffer=tf_tree())
    got = ops.fuse("base_footprint").filter((NAN, NAN, 0.0), (NAN, NAN, 1.0)).as_points()
    in_base = laser_to_base(pts)
    expected = in_base[(in_base[:, 2] >= 0.0) & (in_base[:, 2] <= 1.0)]
    np.testing.assert_allclose(got, expected, atol=1e-12)
    # Before the fuse the same filter applies in the laser frame: different points.
    before = PointPerceptionsOps({"laser1": perception(pts)}, tf_buffer=tf_tree())
    got_before = before.filter((NAN, NAN, 0.0), (NAN, NAN, 1.0)).fuse("base_footprint")
    expected_before = laser_to_base(pts[(pts[:, 2] >= 0.0) & (pts[:, 2] <= 1.0)])
    np.testing.assert_allclose(got_before.as_points(), expected_before, atol=1e-12)


# -- downsample --------------------------------------------------------------------------------
@pytest.mark.parametrize("resolution", [0.05, 0.3, 1.0, 7.0])
def test_downsample_keeps_the_first_point_of_each_floor_voxel(resolution):
    pts = cloud(2000, seed=5)
    got = PointPerceptionsOps([perception(pts)]).downsample(resolution).as_points()
    np.testing.assert_array_equal(got, reference_voxel_first(pts, resolution))


def test_downsample_uses_floor_not_truncation_around_zero():
    pts = np.array([[-0.05, 0.0, 0.0], [0.05, 0.0, 0.0], [-0.09, 0.0, 0.0]])
    got = voxel_downsample(pts, 0.1)
    np.testing.assert_array_equal(got, pts[:2])  # -0.05 and 0.05 are in different voxels


def test_downsample_handles_huge_index_ranges_exactly():
    pts = np.array([[-1e6, 0, 0], [1e6, 1e6, 1e6], [1e6, 1e6, 1e6 + 1e-4], [0, -1e6, 3]])
    got = voxel_downsample(pts, 1e-3)
    np.testing.assert_array_equal(got, reference_voxel_first(pts, 1e-3))


def test_downsample_rejects_a_bad_resolution():
    for bad in (0.0, -1.0, NAN, math.inf):
        with pytest.raises(ValueError, match="resolution"):
            PointPerceptionsOps([perception(cloud(5))]).downsample(bad)


@settings(max_examples=50, deadline=None)
@given(
    arrays(np.float64, st.tuples(st.integers(0, 60), st.just(3)),
           elements=st.floats(-100, 100, allow_nan=False, width=32)),
    st.sampled_from([0.01, 0.1, 0.25, 1.0, 3.0]),
)  # fmt: skip
def test_downsample_property(points, resolution):
    np.testing.assert_array_equal(
        voxel_downsample(points, resolution), reference_voxel_first(points, resolution)
    )


# -- collapse ---------------------------------------------------------------------------------
def test_collapse_forces_the_given_coordinates_only():
    pts = cloud(100)
    got = PointPerceptionsOps([perception(pts)]).collapse((NAN, NAN, 0.1)).as_points()
    expected = pts.copy()
    expected[:, 2] = 0.1
    np.testing.assert_array_equal(got, expected)


def test_collapse_then_downsample_is_a_2d_grid():
    pts = cloud(3000, seed=8)
    got = PointPerceptionsOps([perception(pts)]).collapse((NAN, NAN, 0.0)).downsample(0.5)
    flat = pts.copy()
    flat[:, 2] = 0.0
    np.testing.assert_array_equal(got.as_points(), reference_voxel_first(flat, 0.5))


# -- fuse ---------------------------------------------------------------------------------------
def test_fuse_transforms_every_perception_and_concatenates():
    a, b = cloud(100, seed=1), cloud(50, seed=2)
    ops = PointPerceptionsOps(
        {"laser1": perception(a, "laser"), "base_cam": perception(b, "base_footprint", 10.5)},
        tf_buffer=tf_tree(),
    ).fuse("base_footprint")
    np.testing.assert_allclose(ops.as_points(), np.vstack((laser_to_base(a), b)), atol=1e-12)
    assert ops.frame_id == "base_footprint" and ops.stamp == 10.5


def test_fuse_uses_each_perception_stamp_through_a_moving_frame():
    pts = np.array([[1.0, 0.0, 0.0]])
    buffer = tf_tree()
    ops = PointPerceptionsOps([perception(pts, "base_footprint", stamp=10.0)], tf_buffer=buffer)
    np.testing.assert_allclose(ops.fuse("odom").as_points(), [[3.0, 0, 0]])  # x = 1 + 2 at t=10
    explicit = PointPerceptionsOps([perception(pts, "base_footprint", 10.0)], tf_buffer=buffer)
    np.testing.assert_allclose(explicit.fuse("odom", stamp=9.5).as_points(), [[2.5, 0, 0]])
    assert explicit.stamp == 9.5


def test_fuse_outside_the_tf_window_uses_latest_unless_exact_time(caplog):
    pts = np.array([[1.0, 0.0, 0.0]])
    buffer = tf_tree()
    late = perception(pts, "base_footprint", stamp=11.5)  # TF only known up to 11.0
    got = PointPerceptionsOps({"laser1": late}, tf_buffer=buffer).fuse("odom").as_points()
    np.testing.assert_allclose(got, [[4.0, 0, 0]])
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        ops = PointPerceptionsOps({"laser_late": late}, tf_buffer=buffer)
        exact = ops.fuse("odom", exact_time=True).as_points()
    assert exact.shape == (0, 3)
    assert "Perception 'laser_late' skipped" in caplog.text
    assert "'base_footprint'" in caplog.text and "'odom'" in caplog.text


def test_fuse_skips_an_unknown_frame_with_a_warning_naming_sensor_and_frames(caplog):
    good = perception(cloud(10), "laser")
    lost = perception(cloud(10), "mystery_frame")
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        got = PointPerceptionsOps({"laser1": good, "cam9": lost}, tf_buffer=tf_tree())
        points = got.fuse("base_footprint").as_points()
    np.testing.assert_allclose(points, laser_to_base(good.points), atol=1e-12)
    assert "Perception 'cam9' skipped" in caplog.text
    assert "'mystery_frame'" in caplog.text and "'base_footprint'" in caplog.text


def test_fuse_never_uses_a_nan_transform(caplog):
    buffer = tf_tree()
    with caplog.at_level(logging.WARNING):
        buffer.set_transform_values("base_footprint", "laser2", 0.0, (NAN, 0, 0, 0, 0, 0, 1), "x")
    ops = PointPerceptionsOps({"laser2": perception(cloud(10), "laser2")}, tf_buffer=buffer)
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        points = ops.fuse("base_footprint").as_points()
    assert points.shape == (0, 3)
    assert "'laser2'" in caplog.text


def test_fuse_needs_a_target_frame():
    with pytest.raises(ValueError, match="target_frame"):
        PointPerceptionsOps([perception(cloud(3))]).fuse("")


# -- inputs and outputs ------------------------------------------------------------------------
def test_invalid_perceptions_are_skipped():
    pts = cloud(20)
    ops = PointPerceptionsOps([perception(pts), perception(cloud(30), valid=False)])
    np.testing.assert_array_equal(ops.as_points(), pts)
    assert PointPerceptionsOps([perception(pts, valid=False)]).as_points().shape == (0, 3)
    assert len(PointPerceptionsOps({})) == 0


def test_results_are_writable_copies_and_perceptions_are_never_modified():
    p = perception(cloud(30))
    original = p.points.copy()
    for ops in (
        PointPerceptionsOps([p]),
        PointPerceptionsOps([p]).collapse((0.0, NAN, NAN)),
        PointPerceptionsOps([p]).fuse("laser"),
        PointPerceptionsOps([p]).filter((NAN,) * 3, (NAN,) * 3),
    ):
        out = ops.as_points()
        assert out.flags.writeable
        out += 1.0
    np.testing.assert_array_equal(p.points, original)


def test_items_must_be_point_perceptions():
    with pytest.raises(TypeError, match="'lidar' is a str"):
        PointPerceptionsOps({"lidar": "not a perception"})  # type: ignore[dict-item]


def test_chaining_as_the_plugins_do_matches_a_direct_computation():
    """The obstacle-filter chain: downsample, fuse, filter, collapse, downsample."""
    pts = cloud(5000, seed=11)
    got = (
        PointPerceptionsOps({"laser1": perception(pts)}, tf_buffer=tf_tree())
        .downsample(0.1)
        .fuse("base_footprint")
        .filter((NAN, NAN, 0.1), (NAN, NAN, NAN))
        .collapse((NAN, NAN, 0.1))
        .downsample(0.1)
        .as_points()
    )
    step = laser_to_base(reference_voxel_first(pts, 0.1))
    step = step[step[:, 2] >= 0.1]
    step[:, 2] = 0.1
    np.testing.assert_allclose(got, reference_voxel_first(step, 0.1), atol=1e-12)
