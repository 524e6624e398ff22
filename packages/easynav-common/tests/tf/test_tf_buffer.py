"""TFBuffer: interpolation, chains, static vs dynamic, errors, window, NaN, threads."""

from __future__ import annotations

import logging
import math
import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp
from tf_test_helpers import matrix, stamped_matrix, yaw_values

from easynav.common.tf import (
    ConnectivityError,
    ExtrapolationError,
    FrameLookupError,
    TFBuffer,
    TransformError,
)
from easynav.core.types import Header, Transform, TransformStamped


def robot_tree(buffer: TFBuffer) -> None:
    """map -> odom (static), odom -> base_link (moving, stamps 0..10), base_link -> laser."""
    buffer.set_transform_values("map", "odom", 0.0, yaw_values(1.0, 2.0, 0.5), "test", True)
    for i in range(11):
        t = float(i)
        buffer.set_transform_values("odom", "base_link", t, yaw_values(0.1 * t, 0.0, 0.1 * t), "t")
    buffer.set_transform_values("base_link", "laser", 0.0, (0.2, 0.0, 0.3, 0, 0, 0, 1), "t", True)


def test_interpolates_translation_linearly_and_rotation_by_slerp():
    buffer = TFBuffer()
    q0 = Rotation.from_euler("xyz", (0.1, -0.2, 0.3))
    q1 = Rotation.from_euler("xyz", (0.7, 0.4, -1.2))
    buffer.set_transform_values("odom", "base", 10.0, (0, 0, 0, *q0.as_quat()), "t")
    buffer.set_transform_values("odom", "base", 12.0, (2.0, -4.0, 1.0, *q1.as_quat()), "t")
    ts = buffer.lookup_transform("odom", "base", 10.5)
    np.testing.assert_allclose(ts.transform.translation, (0.5, -1.0, 0.25), atol=1e-12)
    expected = Slerp([10.0, 12.0], Rotation.concatenate([q0, q1]))([10.5])[0]
    got = Rotation.from_quat(ts.transform.rotation)
    assert (got.inv() * expected).magnitude() < 1e-9
    assert ts.header.stamp == 10.5
    assert ts.header.frame_id == "odom" and ts.child_frame_id == "base"


def test_exact_sample_times_return_the_samples():
    buffer = TFBuffer()
    robot_tree(buffer)
    ts = buffer.lookup_transform("odom", "base_link", 3.0)
    np.testing.assert_allclose(stamped_matrix(ts), matrix(*yaw_values(0.3, 0.0, 0.3)), atol=1e-12)


def test_chain_through_the_tree_equals_the_product_of_matrices():
    buffer = TFBuffer()
    robot_tree(buffer)
    t = 4.0
    expected = (
        matrix(*yaw_values(1.0, 2.0, 0.5))
        @ matrix(*yaw_values(0.4, 0.0, 0.4))
        @ matrix(0.2, 0.0, 0.3, 0, 0, 0, 1)
    )
    np.testing.assert_allclose(
        stamped_matrix(buffer.lookup_transform("map", "laser", t)), expected, atol=1e-12
    )
    # And the other way round: the inverse.
    np.testing.assert_allclose(
        stamped_matrix(buffer.lookup_transform("laser", "map", t)),
        np.linalg.inv(expected),
        atol=1e-12,
    )


def test_chain_between_siblings_goes_through_their_common_ancestor():
    buffer = TFBuffer()
    robot_tree(buffer)
    buffer.set_transform_values("base_link", "camera", 0.0, yaw_values(0.1, 0.2, 1.0, 0.5), "t", 1)
    expected = np.linalg.inv(matrix(0.2, 0.0, 0.3, 0, 0, 0, 1)) @ matrix(
        *yaw_values(0.1, 0.2, 1.0, 0.5)
    )
    got = stamped_matrix(buffer.lookup_transform("laser", "camera", 2.0))
    np.testing.assert_allclose(got, expected, atol=1e-12)


def test_same_frame_is_identity():
    buffer = TFBuffer()
    robot_tree(buffer)
    ts = buffer.lookup_transform("laser", "laser")
    np.testing.assert_allclose(stamped_matrix(ts), np.eye(4))


def test_latest_common_time_is_the_oldest_newest_stamp_on_the_chain():
    buffer = TFBuffer()
    robot_tree(buffer)  # odom->base_link up to 10
    buffer.set_transform_values("earth", "map", 6.5, (0, 0, 0, 0, 0, 0, 1), "t")
    buffer.set_transform_values("earth", "map", 7.5, (1, 0, 0, 0, 0, 0, 1), "t")
    ts = buffer.lookup_transform("earth", "laser")  # None: latest common time
    assert ts.header.stamp == 7.5
    assert buffer.lookup_transform("earth", "laser", 0.0).header.stamp == 7.5
    assert buffer.latest_common_time("earth", "laser") == 7.5
    assert buffer.lookup_transform("odom", "laser").header.stamp == 10.0


def test_static_chain_holds_at_any_time_and_reports_stamp_zero():
    buffer = TFBuffer()
    buffer.set_transform_values("base_link", "laser", 5.0, (1, 0, 0, 0, 0, 0, 1), "t", True)
    for when in (None, 0.0, 1.0, 1e9):
        ts = buffer.lookup_transform("base_link", "laser", when)
        np.testing.assert_allclose(ts.transform.translation, (1, 0, 0))
    assert buffer.lookup_transform("base_link", "laser").header.stamp == 0.0


def test_clear_forgets_everything_or_with_keep_static_only_the_dynamic_transforms():
    """A time jump keeps the static transforms (their publishers do not send them again), a
    new system forgets everything; either way the new time line's transforms are taken."""
    buffer = TFBuffer()
    robot_tree(buffer)
    buffer.clear(keep_static=True)
    assert buffer.frames() == ["base_link", "laser", "map", "odom"]
    assert not buffer.can_transform("odom", "base_link")
    np.testing.assert_allclose(buffer.lookup_transform("base_link", "laser").transform.translation,
                               (0.2, 0.0, 0.3))
    # the new time line, from 1 s: older than the old window, taken all the same
    buffer.set_transform_values("odom", "base_link", 1.0, yaw_values(5.0, 0.0, 0.0), "t")
    assert buffer.lookup_transform("map", "laser").header.stamp == 1.0
    buffer.clear()
    assert buffer.frames() == []


def test_after_a_clear_with_refuse_after_the_old_time_line_is_refused_until_ended(
    caplog, monkeypatch
):
    """The clock jumped back from 60 s to 0 s: transforms stamped after 30 s (still queued
    from the old run) are refused with a warning, the new run's taken, until the listener ends
    the refusal (its clock got to 30 s) or 5 s of monotonic time passed (transforms stamped on
    another clock than the listener's are not refused for good). Static transforms are never
    refused."""
    from easynav.common.tf import tf_buffer

    now = [100.0]
    monkeypatch.setattr(tf_buffer, "_monotonic", lambda: now[0])
    buffer = TFBuffer()
    buffer.set_transform_values("odom", "base_link", 60.0, yaw_values(5.0, 0.0, 0.0), "old")
    buffer.clear(keep_static=True, refuse_after=30.0)
    assert buffer.refusing_after == 30.0
    assert not buffer.set_transform_values("odom", "base_link", 60.05, yaw_values(5, 0, 0), "old")
    assert "refused: stamp 60.050 is on the time line before the clock changed" in caplog.text
    assert buffer.set_transform_values("base_link", "laser", 99.0, (0, 0, 0, 0, 0, 0, 1), "s", True)
    for t in (0.5, 10.0, 29.5):
        assert buffer.set_transform_values("odom", "base_link", t, yaw_values(t, 0, 0), "new")
    assert not buffer.set_transform_values("odom", "base_link", 31.0, yaw_values(0, 0, 0), "x")
    buffer.end_refusal()
    assert buffer.refusing_after is None
    assert buffer.set_transform_values("odom", "base_link", 31.0, yaw_values(31, 0, 0), "new")
    assert buffer.lookup_transform("odom", "base_link").header.stamp == 31.0

    buffer.clear(keep_static=True, refuse_after=30.0)
    assert not buffer.set_transform_values("odom", "base_link", 1.8e9, yaw_values(0, 0, 0), "w")
    now[0] += tf_buffer._REFUSAL_MAX_WALL + 0.1
    assert buffer.set_transform_values("odom", "base_link", 1.8e9, yaw_values(0, 0, 0), "w")
    assert buffer.refusing_after is None


def test_dynamic_lookup_outside_the_range_is_an_extrapolation_error_naming_everything():
    buffer = TFBuffer()
    robot_tree(buffer)
    with pytest.raises(ExtrapolationError) as info:
        buffer.lookup_transform("map", "laser", 12.5)
    text = str(info.value)
    for part in ("'laser'", "'map'", "12.500", "'odom' -> 'base_link'", "[0.000, 10.000]"):
        assert part in text, text
    assert "2.500 s after the newest data" in text
    late = TFBuffer()
    late.set_transform_values("odom", "base", 5.0, (0, 0, 0, 0, 0, 0, 1), "t")
    late.set_transform_values("odom", "base", 6.0, (0, 0, 0, 0, 0, 0, 1), "t")
    with pytest.raises(ExtrapolationError, match="0.500 s before the oldest data"):
        late.lookup_transform("odom", "base", 4.5)
    assert isinstance(info.value, TransformError) and isinstance(info.value, LookupError)
    assert not buffer.can_transform("map", "laser", 12.5)
    assert buffer.can_transform("map", "laser", 9.99)


def test_unknown_frame_and_disconnected_trees():
    buffer = TFBuffer()
    robot_tree(buffer)
    with pytest.raises(FrameLookupError, match="frame 'camera' does not exist") as info:
        buffer.lookup_transform("map", "camera")
    assert "known frames: base_link, laser, map, odom" in str(info.value)
    buffer.set_transform_values("world", "other_robot", 0.0, (0, 0, 0, 0, 0, 0, 1), "t", True)
    with pytest.raises(ConnectivityError, match="different TF trees") as info:
        buffer.lookup_transform("map", "other_robot")
    assert "root 'world'" in str(info.value) and "root 'map'" in str(info.value)
    assert isinstance(info.value, LookupError)


def test_leading_slash_is_ignored_as_in_tf2():
    buffer = TFBuffer()
    robot_tree(buffer)
    a = buffer.lookup_transform("/map", "/laser", 2.0)
    b = buffer.lookup_transform("map", "laser", 2.0)
    np.testing.assert_allclose(stamped_matrix(a), stamped_matrix(b))
    assert a.header.frame_id == "map"


def test_cache_window_drops_old_samples_and_rejects_older_data(caplog):
    buffer = TFBuffer(cache_time=2.0)
    for i in range(11):
        buffer.set_transform_values("odom", "base", float(i), (float(i), 0, 0, 0, 0, 0, 1), "t")
    assert buffer.can_transform("odom", "base", 8.0)
    with pytest.raises(ExtrapolationError, match=r"\[8.000, 10.000\]"):
        buffer.lookup_transform("odom", "base", 7.5)
    with caplog.at_level(logging.WARNING, logger="easynav.tf"):
        assert not buffer.set_transform_values("odom", "base", 5.0, (0, 0, 0, 0, 0, 0, 1), "late")
    assert "older than the 2 s window" in caplog.text and "'late'" in caplog.text


def test_out_of_order_samples_are_sorted_and_same_stamp_replaces():
    buffer = TFBuffer()
    buffer.set_transform_values("odom", "base", 3.0, (3, 0, 0, 0, 0, 0, 1), "t")
    buffer.set_transform_values("odom", "base", 1.0, (1, 0, 0, 0, 0, 0, 1), "t")
    buffer.set_transform_values("odom", "base", 2.0, (5, 0, 0, 0, 0, 0, 1), "t")
    buffer.set_transform_values("odom", "base", 2.0, (2, 0, 0, 0, 0, 0, 1), "t")
    for t in (1.0, 1.5, 2.0, 2.5, 3.0):
        x = buffer.lookup_transform("odom", "base", t).transform.translation[0]
        assert x == pytest.approx(t)


@pytest.mark.parametrize(
    "values",
    [
        (math.nan, 0, 0, 0, 0, 0, 1),
        (0, math.inf, 0, 0, 0, 0, 1),
        (0, 0, 0, 0, 0, math.nan, 1),
        (0, 0, 0, 0, 0, 0, 0),  # zero quaternion: no rotation at all
    ],
)
def test_nan_or_degenerate_transforms_are_rejected_with_a_warning(values, caplog):
    buffer = TFBuffer()
    buffer.set_transform_values("odom", "base", 1.0, (1, 0, 0, 0, 0, 0, 1), "good")
    with caplog.at_level(logging.WARNING, logger="easynav.tf"):
        assert not buffer.set_transform_values("odom", "base", 2.0, values, "broken_driver")
    assert "'odom' -> 'base'" in caplog.text and "broken_driver" in caplog.text
    ts = buffer.lookup_transform("odom", "base")
    assert ts.header.stamp == 1.0 and np.all(np.isfinite(ts.transform.translation))


def test_bad_frame_names_and_stamps_are_rejected(caplog):
    buffer = TFBuffer()
    with caplog.at_level(logging.WARNING, logger="easynav.tf"):
        assert not buffer.set_transform_values("", "base", 1.0, (0, 0, 0, 0, 0, 0, 1), "a")
        assert not buffer.set_transform_values("base", "base", 1.0, (0, 0, 0, 0, 0, 0, 1), "b")
        assert not buffer.set_transform_values("o", "base", math.nan, (0, 0, 0, 0, 0, 0, 1), "c")
    assert "empty frame name" in caplog.text
    assert "cannot be its own parent" in caplog.text
    assert "not a finite" in caplog.text
    assert buffer.frames() == []


def test_quaternions_are_normalised_on_the_way_in():
    buffer = TFBuffer()
    buffer.set_transform_values("odom", "base", 0.0, (0, 0, 0, 0, 0, 2.0, 2.0), "t", True)
    q = buffer.lookup_transform("odom", "base").transform.rotation
    np.testing.assert_allclose(q, (0, 0, math.sqrt(0.5), math.sqrt(0.5)))


def test_set_transform_accepts_native_transform_stamped():
    buffer = TFBuffer()
    ts = TransformStamped(
        header=Header(stamp=3.0, frame_id="odom"),
        child_frame_id="base",
        transform=Transform(np.array((1.0, 2.0, 3.0)), np.array((0.0, 0.0, 0.0, 1.0))),
    )
    assert buffer.set_transform(ts, "test")
    np.testing.assert_allclose(buffer.lookup_transform("odom", "base", 3.0).transform.translation,
                               (1, 2, 3))  # fmt: skip


def test_reparenting_a_frame_changes_the_chain():
    buffer = TFBuffer()
    buffer.set_transform_values("a", "x", 0.0, (1, 0, 0, 0, 0, 0, 1), "t", True)
    buffer.set_transform_values("b", "a", 0.0, (0, 10, 0, 0, 0, 0, 1), "t", True)
    assert buffer.lookup_transform("b", "x").transform.translation[1] == 10
    buffer.set_transform_values("c", "x", 0.0, (2, 0, 0, 0, 0, 0, 1), "t", True)
    with pytest.raises(ConnectivityError):
        buffer.lookup_transform("b", "x")
    assert buffer.lookup_transform("c", "x").transform.translation[0] == 2


def test_a_loop_in_the_tree_is_a_connectivity_error_not_a_hang():
    buffer = TFBuffer()
    buffer.set_transform_values("a", "b", 0.0, (1, 0, 0, 0, 0, 0, 1), "t", True)
    buffer.set_transform_values("b", "a", 0.0, (1, 0, 0, 0, 0, 0, 1), "t", True)
    buffer.set_transform_values("c", "d", 0.0, (1, 0, 0, 0, 0, 0, 1), "t", True)
    with pytest.raises(ConnectivityError, match="loop"):
        buffer.lookup_transform("d", "a")


def test_cache_time_must_be_positive():
    with pytest.raises(ValueError, match="cache_time"):
        TFBuffer(cache_time=0.0)
    with pytest.raises(ValueError, match="cache_time"):
        TFBuffer().set_cache_time(math.nan)


def test_concurrent_writers_and_readers_see_consistent_transforms():
    """A robot moving at 1 m/s along x: every lookup must give x == stamp, from any thread."""
    buffer = TFBuffer(cache_time=1000.0)
    buffer.set_transform_values("odom", "base", 0.0, (0, 0, 0, 0, 0, 0, 1), "t")
    errors: list[str] = []
    done = threading.Event()

    def writer():
        for i in range(1, 3000):
            buffer.set_transform_values("odom", "base", i * 0.01, (i * 0.01, 0, 0, 0, 0, 0, 1), "t")
        done.set()

    def reader():
        while not done.is_set():
            stamp, values = buffer.lookup_transform_values("odom", "base")
            if abs(values[0] - stamp) > 1e-9:
                errors.append(f"x {values[0]} at stamp {stamp}")

    threads = [threading.Thread(target=writer)]
    threads += [threading.Thread(target=reader) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=30)
    assert not errors, errors[:3]


_coord = st.floats(-50, 50, allow_nan=False)
_angle = st.floats(-math.pi, math.pi, allow_nan=False)
_pose = st.tuples(_coord, _coord, _coord, _angle, _angle, _angle)


@settings(max_examples=60, deadline=None)
@given(st.lists(_pose, min_size=1, max_size=6), st.integers(0, 5))
def test_any_chain_equals_the_matrix_product(poses, split):
    """Frames f0 <- f1 <- ... <- fn; looking up fk <- fn equals the product of matrices."""
    buffer = TFBuffer()
    mats = []
    for i, (x, y, z, r, p, yw) in enumerate(poses):
        q = Rotation.from_euler("xyz", (r, p, yw)).as_quat()
        buffer.set_transform_values(f"f{i}", f"f{i + 1}", 0.0, (x, y, z, *q), "t", True)
        mats.append(matrix(x, y, z, *q))
    n = len(poses)
    k = min(split, n)
    expected = np.eye(4)
    for m in mats[k:]:
        expected = expected @ m
    got = stamped_matrix(buffer.lookup_transform(f"f{k}", f"f{n}"))
    np.testing.assert_allclose(got, expected, atol=1e-9 * max(1.0, np.abs(expected).max()))
    back = stamped_matrix(buffer.lookup_transform(f"f{n}", f"f{k}"))
    np.testing.assert_allclose(back @ expected, np.eye(4), atol=1e-8)
