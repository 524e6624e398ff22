"""ColisionChecker without ROS: the box, commands into a point and past it, parameters."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.core.plugins import DictParameters
from easynav.core.plugins.declarations import ParameterValueError, read_parameters
from easynav.system.colision_checker import COLISION_CHECKER_PARAMETERS, ColisionChecker


def pts(*xy, z=0.2):
    return np.array([(x, y, z) for x, y in xy], dtype=float)


def test_box_grows_with_the_stopping_distance():
    checker = ColisionChecker()  # r 0.35, m 0.1, a 0.5, z [0, 0.5]
    low, high = checker.box(0.5)
    assert low == pytest.approx((-0.45, -0.45, 0.0))
    assert high == pytest.approx((0.45 + 0.25, 0.45, 0.5))
    low, high = checker.box(-0.5)
    assert low[0] == pytest.approx(-0.7) and high[0] == pytest.approx(0.45)


def test_stops_a_command_heading_into_a_point():
    checker = ColisionChecker()
    hit = checker.check(pts((0.6, 0.0)), 0.5, 0.0)
    assert hit is not None
    # The centre-to-point distance at the stopping time T = 1 s (0.6 - 0.5).
    assert hit.time == pytest.approx(1.0) and hit.distance == pytest.approx(0.1)
    # Slightly to the side, still inside the radius when passing.
    assert checker.check(pts((0.5, 0.3)), 0.5, 0.0) is not None
    # Reversing into a point behind.
    assert checker.check(pts((-0.6, 0.0)), -0.5, 0.0) is not None


def test_passes_a_command_that_misses_the_point():
    checker = ColisionChecker()
    # Beside the robot's path, farther than its radius.
    assert checker.check(pts((0.6, 0.4)), 0.5, 0.0) is None
    # Beyond the stopping distance: braking stops short of it.
    assert checker.check(pts((1.0, 0.0)), 0.5, 0.0) is None
    # Behind while driving forwards, above the robot, below z_min, turning in place.
    assert checker.check(pts((-0.3, 0.0)), 0.5, 0.0) is None
    assert checker.check(pts((0.6, 0.0), z=0.8), 0.5, 0.0) is None
    assert checker.check(pts((0.6, 0.0), z=-0.1), 0.5, 0.0) is None
    assert checker.check(pts((0.3, 0.0)), 0.0, 1.0) is None
    assert checker.check(np.empty((0, 3)), 0.5, 0.0) is None


def test_turning_away_misses_a_point_that_straight_motion_hits():
    checker = ColisionChecker(robot_radius=0.2, brake_acc=1.0)
    point = pts((0.45, 0.0))
    assert checker.check(point, 0.6, 0.0) is not None
    # Turning hard left: the point swings to the right, outside the radius.
    assert checker.check(point, 0.6, 3.0) is None


def test_matches_a_direct_closest_approach_computation():
    rng = np.random.default_rng(1)
    checker = ColisionChecker()
    for _ in range(200):
        p = rng.uniform((-0.5, -0.5, 0.0), (0.8, 0.5, 0.5))
        v, w = rng.uniform(0.05, 0.5), rng.uniform(-1.0, 1.0)
        rel = np.array((-v + w * p[1], -w * p[0]))
        # Sample the relative motion densely up to the stopping time.
        ts = np.linspace(0.0, v / 0.5, 2001)
        d = np.hypot(p[0] + rel[0] * ts, p[1] + rel[1] * ts)
        approaching = -(p[0] * rel[0] + p[1] * rel[1]) > 0.0
        low, high = checker.box(v)
        inside = all(low[i] <= p[i] <= high[i] for i in range(3))
        expected = inside and approaching and d.min() <= 0.35 - 1e-6
        got = checker.check(p[None, :], v, w) is not None
        if abs(d.min() - 0.35) > 1e-3:
            assert got == expected, (p, v, w)


def test_parameters_are_declared_with_the_original_names_and_defaults():
    """The original's names and defaults, except the robot's shape: robot_radius and
    robot_height are deprecated copies of robot_geometry's (unset, NaN, by default)."""
    values = dict(read_parameters(COLISION_CHECKER_PARAMETERS, DictParameters(), ""))
    assert math.isnan(values.pop("colision_checker.robot_radius"))
    assert math.isnan(values.pop("colision_checker.robot_height"))
    assert values == {
        "colision_checker.active": False,
        "colision_checker.debug_markers": False,
        "colision_checker.brake_acc": 0.5,
        "colision_checker.safety_margin": 0.1,
        "colision_checker.z_min_filter": 0.0,
        "colision_checker.downsample_leaf_size": 0.1,
    }
    checker = ColisionChecker.from_parameters(
        {**values, "colision_checker.robot_radius": 0.35, "colision_checker.robot_height": 0.5})
    assert checker.robot_radius == 0.35 and checker.downsample_leaf_size == 0.1
    with pytest.raises(ParameterValueError, match="colision_checker.robot_radius = -0.1"):
        read_parameters(
            COLISION_CHECKER_PARAMETERS,
            DictParameters({"colision_checker.robot_radius": -0.1}),
            "",
        )
    with pytest.raises(ParameterValueError, match="colision_checker.brake_acc = 0.0"):
        read_parameters(
            COLISION_CHECKER_PARAMETERS,
            DictParameters({"colision_checker.brake_acc": 0.0}),
            "",
        )
    with pytest.raises(ValueError, match="robot_radius"):
        ColisionChecker(robot_radius=math.nan)
    with pytest.raises(ValueError, match="robot_height = -0.5"):
        ColisionChecker(robot_height=-0.5)
