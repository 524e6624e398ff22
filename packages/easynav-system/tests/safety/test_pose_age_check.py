"""PoseAgeCheck: diagnostics.robot_pose for old or non-finite poses."""

import math

import pytest

from easynav.core.types import DiagnosticLevel, Header, Odometry, Pose
from easynav.system.safety import PoseAgeCheck


def pose(stamp, x=1.0):
    return Odometry(header=Header(stamp=stamp, frame_id="map"), pose=Pose(x=x))


def test_nothing_is_checked_until_a_pose_exists():
    assert PoseAgeCheck(1.0).check(None, 100.0) == (True, None)


def test_a_fresh_pose_is_usable_and_writes_nothing():
    assert PoseAgeCheck(1.0).check(pose(99.5), 100.0) == (True, None)


def test_an_old_pose_is_an_error_then_ok_when_usable_again():
    check = PoseAgeCheck(1.0)
    usable, change = check.check(pose(98.0), 100.0)
    assert not usable
    assert change.level is DiagnosticLevel.ERROR
    assert change.name == "robot_pose" and change.hardware_id == "system_node"
    assert "safety.max_pose_age = 1 s" in change.message and change.values["age_s"] == "2.000"
    assert check.check(pose(98.0), 100.1) == (False, None)  # unchanged: not written again
    usable, change = check.check(pose(100.0), 100.2)
    assert usable and change.level is DiagnosticLevel.OK


@pytest.mark.parametrize("bad", [pose(100.0, x=math.nan), pose(math.nan)])
def test_a_non_finite_pose_is_an_error(bad):
    usable, change = PoseAgeCheck(1.0).check(bad, 100.0)
    assert not usable and "not finite" in change.message


def test_zero_turns_it_off():
    assert PoseAgeCheck(0.0).check(pose(0.0, x=math.nan), 100.0) == (True, None)


def test_invalid_max_pose_age():
    with pytest.raises(ValueError, match="safety.max_pose_age"):
        PoseAgeCheck(-1.0)
