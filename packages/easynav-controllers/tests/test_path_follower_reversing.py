"""The path follower at cusps, on a simulated unicycle: turning round at them (the default) and
reversing through them (allow_reversing)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from easynav.controllers import ARRIVED, SimplePathFollower
from easynav.controllers.path_follower import cusp_pieces, path_segments
from easynav.core.robot import RobotLimits

LIMITS = replace(RobotLimits(), min_linear_vel=-0.3)


def simulate(follower, path, start, limits=LIMITS, dt=1 / 30, seconds=60.0):
    x, y, yaw = start
    trace = []
    for _ in range(int(seconds / dt)):
        v, w, state = follower.compute((x, y, yaw), path, dt, limits)
        assert limits.min_linear_vel - 1e-12 <= v <= limits.max_linear_vel + 1e-12
        assert abs(w) <= limits.max_angular_vel + 1e-12
        trace.append((x, y, yaw, v, w))
        if state == ARRIVED:
            return np.array(trace), True
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        yaw += w * dt
    return np.array(trace), False


def straight(x0, x1, step=0.05, yaw=0.0):
    xs = np.arange(x0, x1, step if x1 > x0 else -step)
    return np.array([(x, 0.0, yaw) for x in list(xs) + [x1]])


def forward_then_reverse_arc() -> np.ndarray:
    """Forward 1.5 m along x (yaw 0), then reverse along a left-hand arc of radius 1 m (the
    car backs up turning its rear to +y): a Reeds–Shepp-like path with one cusp."""
    forward = straight(0.0, 1.5)
    t = np.linspace(0.0, math.pi / 2, 40)[1:]
    # Centre (1.5, 1.0); the car backs along the circle, heading = tangent + pi.
    cx, cy, r = 1.5, 1.0, 1.0
    phi = -math.pi / 2 - t  # from the bottom of the circle, clockwise = backwards
    arc = np.stack([cx + r * np.cos(phi), cy + r * np.sin(phi), -t], axis=1)
    return np.concatenate([forward, arc])


def test_segments_are_cut_at_cusps():
    path = forward_then_reverse_arc()
    cusp = len(straight(0.0, 1.5)) - 1
    assert path_segments(path) == [(0, cusp, 1), (cusp, len(path) - 1, -1)]
    assert path_segments(straight(0.0, 1.0)) == [(0, 20, 1)]
    assert path_segments(straight(1.0, 0.0)) == [(0, 20, -1)]
    assert path_segments(np.array([[1.0, 2.0, 0.0]])) == [(0, 0, 1)]
    # A repeated pose keeps the direction of the step before it.
    doubled = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    assert path_segments(doubled) == [(0, 3, 1)]


def test_cusp_pieces_cut_where_the_path_turns_back_whatever_the_yaw():
    path = forward_then_reverse_arc()
    cusp = len(straight(0.0, 1.5)) - 1
    assert cusp_pieces(path[:, :2]) == [(0, cusp, 1), (cusp, len(path) - 1, 1)]
    # A right angle is a corner, not a cusp; a repeated pose is skipped; a turn sharper than a
    # right angle is a cusp (Nav2's rule).
    corner = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    assert cusp_pieces(corner) == [(0, 3, 1)]
    hairpin = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.1]])
    assert cusp_pieces(hairpin) == [(0, 2, 1), (2, 3, 1)]
    assert cusp_pieces(np.zeros((1, 2))) == [(0, 0, 1)]


@pytest.mark.parametrize("estimate_noise", [0.0, 0.01])
def test_a_robot_that_does_not_reverse_turns_round_at_a_cusp(estimate_noise):
    # Followed as one path, the carrot 0.2 m past the projection folds back from the cusp onto
    # a robot 0.1 m short of it: the heading to it is noise and the robot turned on the spot
    # there for minutes (an OMPL Reeds-Shepp run in the depot). Cut at the cusp, it drives to
    # the cusp, turns round and drives the rest forward.
    path = forward_then_reverse_arc()
    follower = SimplePathFollower(look_ahead_dist=0.2)
    rng = np.random.default_rng(3)
    x, y, yaw = 0.0, 0.0, 0.0
    dt, limits = 1 / 30, RobotLimits()
    trace = []
    for _ in range(int(60.0 / dt)):
        estimate = (x, y, yaw) + rng.normal(0.0, estimate_noise, 3)
        v, w, state = follower.compute(estimate, path, dt, limits)
        trace.append((x, y, v))
        if state == ARRIVED:
            break
        x, y, yaw = x + v * math.cos(yaw) * dt, y + v * math.sin(yaw) * dt, yaw + w * dt
    assert state == ARRIVED
    trace = np.array(trace)
    assert (trace[:, 2] >= 0.0).all()
    assert np.hypot(trace[:, 0] - 1.5, trace[:, 1]).min() <= 0.1 + 0.01  # went to the cusp
    assert math.hypot(x - path[-1, 0], y - path[-1, 1]) <= 0.05 + 3 * estimate_noise


def drive(follower, path, start, seconds=60.0, reset_at=None):
    """The unicycle driven by ``follower``, ``reset()`` once when the robot first comes within
    0.1 m of ``reset_at``: the trace of (x, y, v), whether it arrived, the step of the reset."""
    x, y, yaw = start
    dt, limits = 1 / 30, RobotLimits()
    trace, reset_step = [], None
    for step in range(int(seconds / dt)):
        if reset_step is None and reset_at is not None and (
            math.hypot(x - reset_at[0], y - reset_at[1]) < 0.1
        ):
            follower.reset()
            reset_step = step
        v, w, state = follower.compute((x, y, yaw), path, dt, limits)
        trace.append((x, y, v))
        if state == ARRIVED:
            return np.array(trace), True, reset_step
        x, y, yaw = x + v * math.cos(yaw) * dt, y + v * math.sin(yaw) * dt, yaw + w * dt
    return np.array(trace), False, reset_step


def test_a_reset_past_a_cusp_does_not_send_the_robot_back_to_it():
    # A reset (a missed pose, a clock hiccup) keeps the piece the robot is on: the same path
    # goes on from there, not from the cusp it already turned round at.
    path = forward_then_reverse_arc()
    cusp = len(straight(0.0, 1.5)) - 1
    follower = SimplePathFollower(look_ahead_dist=0.2)
    trace, arrived, reset_step = drive(follower, path, (0.0, 0.0, 0.0),
                                       reset_at=path[cusp + 15, :2])
    assert arrived and reset_step is not None
    assert np.hypot(trace[reset_step:, 0] - 1.5, trace[reset_step:, 1]).min() > 0.3


def test_a_new_follower_starts_at_the_piece_nearest_the_robot():
    path = forward_then_reverse_arc()
    follower = SimplePathFollower(look_ahead_dist=0.2)
    follower.compute((0.5, 0.95, -1.4), path, 0.1, RobotLimits())  # near the end of the arc
    assert follower._segment == 1
    follower = SimplePathFollower(look_ahead_dist=0.2)
    follower.compute((0.3, 0.0, 0.0), path, 0.1, RobotLimits())  # on the first leg
    assert follower._segment == 0


def test_a_robot_beyond_a_cusp_goes_on_though_it_never_came_within_the_tolerance():
    # Overshooting a cusp sideways (0.15 m off, beyond the 0.1 m tolerance), the robot is past
    # it along the piece's last step: the next piece starts.
    path = forward_then_reverse_arc()
    follower = SimplePathFollower(look_ahead_dist=0.2)
    follower.compute((1.0, 0.0, 0.0), path, 0.1, RobotLimits())
    assert follower._segment == 0
    follower.compute((1.52, -0.15, 0.0), path, 0.1, RobotLimits())
    assert follower._segment == 1


def test_a_goal_behind_is_reached_backing_up_without_turning_around():
    follower = SimplePathFollower(look_ahead_dist=0.3, allow_reversing=True)
    trace, arrived = simulate(follower, straight(1.0, 0.0), (1.0, 0.02, 0.0))
    assert arrived
    assert (trace[:, 3] <= 1e-12).all() and trace[:, 3].min() < -0.2
    assert np.abs(trace[:, 2]).max() < 0.3  # never turned around
    assert math.hypot(trace[-1, 0], trace[-1, 1]) <= 0.05


def test_without_the_parameter_the_robot_never_reverses():
    follower = SimplePathFollower(look_ahead_dist=0.3)
    trace, arrived = simulate(follower, straight(1.0, 0.0), (1.0, 0.02, 0.0))
    assert arrived and (trace[:, 3] >= 0.0).all()
    assert np.abs(trace[:, 2]).max() > 2.5  # it turned around instead


def test_a_path_with_a_cusp_is_driven_forward_then_in_reverse():
    path = forward_then_reverse_arc()
    follower = SimplePathFollower(look_ahead_dist=0.3, allow_reversing=True)
    trace, arrived = simulate(follower, path, (0.0, 0.0, 0.0))
    assert arrived
    v = trace[:, 3]
    first_reverse = int(np.argmax(v < -1e-9))
    assert (v[:first_reverse] >= 0.0).all() and (v[first_reverse:] <= 1e-12).all()
    # It went to the cusp before reversing.
    assert math.hypot(trace[first_reverse, 0] - 1.5, trace[first_reverse, 1]) <= 0.1 + 0.02
    # It stayed near the path all along and ended on the goal with its yaw.
    d = np.hypot(trace[:, None, 0] - path[None, :, 0], trace[:, None, 1] - path[None, :, 1])
    assert d.min(axis=1).max() < 0.15
    assert math.hypot(trace[-1, 0] - path[-1, 0], trace[-1, 1] - path[-1, 1]) <= 0.05
    assert abs(math.remainder(trace[-1, 2] - path[-1, 2], math.tau)) <= 0.1


def test_a_robot_that_cannot_reverse_drives_every_segment_forward():
    follower = SimplePathFollower(look_ahead_dist=0.3, allow_reversing=True)
    no_reverse = replace(LIMITS, min_linear_vel=0.0)
    trace, arrived = simulate(follower, straight(1.0, 0.0), (1.0, 0.02, 0.0), limits=no_reverse)
    assert arrived and (trace[:, 3] >= 0.0).all()


def test_a_new_path_starts_again_from_its_first_segment():
    follower = SimplePathFollower(look_ahead_dist=0.3, allow_reversing=True)
    path = forward_then_reverse_arc()
    follower.compute((1.5, 0.0, 0.0), path, 0.1, LIMITS)  # at the cusp: second segment
    assert follower._segment == 1
    follower.compute((1.5, 0.0, 0.0), path.copy(), 0.1, LIMITS)  # same path, new array
    assert follower._segment == 1
    follower.compute((0.0, 0.0, 0.0), straight(0.0, 1.0), 0.1, LIMITS)
    assert follower._segment == 0


def test_cusp_tolerance_is_checked():
    with pytest.raises(ValueError, match="cusp_tolerance = -1"):
        SimplePathFollower(cusp_tolerance=-1.0)
    # 0 is never reached: the speed towards the cusp falls with the distance to it.
    with pytest.raises(ValueError, match="cusp_tolerance = 0.0 must be finite and > 0"):
        SimplePathFollower(cusp_tolerance=0.0)


def test_the_simple_controller_passes_the_parameters_to_its_follower():
    from easynav.controllers.simple_controller import SimpleController
    from easynav.core.plugins import DictParameters, PluginContext

    def make(values):
        controller = SimpleController()
        controller.initialize(
            PluginContext(parameters=DictParameters(values), namespace="reversing_test"),
            "simple",
        )
        return controller

    assert not make({}).follower.allow_reversing
    controller = make({"simple.allow_reversing": True, "simple.cusp_tolerance": 0.2})
    assert controller.follower.allow_reversing and controller.follower.cusp_tolerance == 0.2
    controller.apply_parameter("allow_reversing", False)
    assert not controller.follower.allow_reversing


def test_a_short_reverse_at_the_end_of_a_path_does_not_skip_the_way_there():
    # A Reeds–Shepp path as OMPL planned it on the depot: west, north, east, then a few
    # centimetres of reverse into the goal. The robot at the start lies beyond the line of the
    # last step before that cusp; it skipped to the last piece and drove straight at the goal,
    # through a wall. It must follow the way there first.
    west = [(x, 0.0, math.pi) for x in np.arange(0.0, -5.0, -0.1)]
    north = [(-5.0, y, math.pi / 2) for y in np.arange(0.0, 5.1, 0.1)]
    east = [(x, 5.1, 0.0) for x in np.arange(-5.0, 4.95, 0.1)]
    # The last step before the cusp heads south-east: the start lies beyond its line.
    tail = [(5.0, 5.1, 0.0), (5.02, 5.05, -1.2), (5.0, 5.1, 1.57)]
    path = np.array(west + north + east + tail)
    assert len(cusp_pieces(path[:, :2])) >= 2
    forward_only = replace(RobotLimits(), min_linear_vel=0.0)
    trace, arrived = simulate(SimplePathFollower(look_ahead_dist=0.3), path, (0.0, 0.0, math.pi),
                              limits=forward_only, seconds=90.0)
    # It drove the way there: west first, then north, never cutting across to the goal.
    assert trace[:, 0].min() < -4.5 and trace[:, 1].max() > 4.5
    assert trace[int(5.0 * 30), 0] < -1.0  # 5 s in: going west, not towards (5, 5)
    assert arrived
