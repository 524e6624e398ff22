"""Every localizer accepts ``initialpose`` to reset its pose, as in the original EasyNav, through
LocalizerMethodBase.handle_initial_pose (the runtime's localizer node hands it each message)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, LocalizerMethodBase, PluginContext
from easynav.core.types import Odometry, Pose

_namespaces = itertools.count()


class RecordingLocalizer(LocalizerMethodBase):
    """A localizer that only records the poses it is told to continue from."""

    def __init__(self) -> None:
        super().__init__()
        self.poses: list[Odometry] = []

    def update_rt(self, nav_state: NavState) -> None:
        pass

    def update(self, nav_state: NavState) -> None:
        pass

    def on_last_known_pose(self, pose: Odometry) -> None:
        self.poses.append(pose)


def initial_pose(x=2.0, y=-1.0, yaw=0.5, frame="map", variance=0.04, stamp=42.0):
    """The values of one initialpose message, as the runtime hands them over."""
    covariance = np.zeros((6, 6))
    covariance[0, 0] = covariance[1, 1] = variance
    covariance[5, 5] = 0.01
    return frame, stamp, Pose.from_xy_yaw(x, y, yaw), covariance


def make_localizer() -> RecordingLocalizer:
    localizer = RecordingLocalizer()
    context = PluginContext(
        parameters=DictParameters(), namespace=f"initial_pose_test_{next(_namespaces)}"
    )
    localizer.initialize(context, "loc")
    return localizer


def test_a_map_frame_initial_pose_reaches_the_localizer_as_an_odometry():
    localizer = make_localizer()
    localizer.handle_initial_pose(*initial_pose())
    (pose,) = localizer.poses  # by default, as a pose to continue from
    assert (pose.pose.x, pose.pose.y) == pytest.approx((2.0, -1.0))
    assert pose.pose.yaw == pytest.approx(0.5)
    assert pose.header.frame_id == "map" and pose.header.stamp == pytest.approx(42.0)
    assert pose.child_frame_id == "base_footprint"
    assert pose.pose_covariance[0, 0] == pytest.approx(0.04)
    assert pose.pose_covariance[5, 5] == pytest.approx(0.01)
    # An empty frame means the map frame (rviz, ros2 topic pub).
    localizer.handle_initial_pose(*initial_pose(x=3.0, frame=""))
    assert localizer.poses[-1].pose.x == pytest.approx(3.0)


@pytest.mark.parametrize(
    "args",
    [{"frame": "odom"}, {"x": math.nan}, {"variance": math.inf}],
    ids=["other_frame", "nan_pose", "inf_covariance"],
)
def test_a_bad_initial_pose_is_ignored(args):
    localizer = make_localizer()
    localizer.handle_initial_pose(*initial_pose(**args))
    assert localizer.poses == []


def test_an_exception_in_the_hook_is_logged_not_raised():
    localizer = make_localizer()

    def fail(pose):
        raise RuntimeError("broken")

    localizer.on_initial_pose = fail
    localizer.handle_initial_pose(*initial_pose())  # must not raise
