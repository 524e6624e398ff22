"""GoalArrival: the end of an approach, shared by MPPI, Regulated Pure Pursuit and the path
follower.

The goal manager removes a goal when the robot's estimate is within its position tolerance and
its yaw tolerance of it, checked afresh each cycle. A controller that stops anywhere else waits
for a goal that is never reached. So, once the robot is within the position tolerance:

1. it turns in place to the goal's yaw, and goes on turning while up to three times the
   tolerance away (the estimate moves as the robot turns: leaving the turn at the tolerance's
   border would start it again and again; an estimate off the robot's centre, a sensor's frame
   a few centimetres wrong, moves by twice that offset in a half turn);
2. turned, it is arrived only within the tolerance;
3. turned but beyond it (the turn moved the estimate out: seen in the integration matrix, a
   robot stopped 0.16 m from a goal with a 0.15 m tolerance and waited 95 s), it creeps straight
   along its heading, without turning (a turn would move the estimate again), to the point of
   that line nearest the goal;
4. only when that cannot bring it within the tolerance (the goal is off to the side, or behind a
   robot that cannot reverse) does it approach again, as it first did, to half the tolerance,
   then, if that was not enough, to a quarter of it, and so on to a sixteenth (an estimate off
   the robot's centre lands the nearer after the turn, the nearer the approach ended).

A limit: an estimate that sits off the robot's centre by about the tolerance or more (a sensor
frame a few centimetres wrong, with the spec's 0.03 m tolerance) can keep any robot turning and
approaching again, a forward-only one as soon as it is more than a third of the tolerance and
the goal faces back along the approach: a systematic offset is a wrong frame to fix, not noise a
controller can absorb.

The controller keeps its own ways of turning and of approaching; this class only decides which.
"""

from __future__ import annotations

import math

from easynav.controllers.command_limits import limit_command
from easynav.core.types import normalize_angle

#: What the controller does this cycle (see :meth:`GoalArrival.decide`).
TURN = "turn"
ARRIVE = "arrive"
CREEP = "creep"

#: The creep's speed (m/s): slow, a few centimetres to go; proportional to the distance left
#: between its bounds (1/s), so that the robot neither overshoots nor stalls in a drive's dead
#: band.
CREEP_SPEED = 0.1
CREEP_MIN_SPEED = 0.02
CREEP_GAIN = 1.0
#: The creep is done within this distance of the line's nearest point (m) or within half the
#: tolerance of the goal.
CREEP_DONE = 0.01
#: The creep is tried when the goal is at most this share of the tolerance off the heading's line:
#: it then ends within the tolerance with a margin.
CREEP_LATERAL = 0.7
#: The turn to the goal's yaw goes on while the robot is within this many tolerances of it, plus
#: TURN_MARGIN (m): an estimate off the robot's centre moves by twice that offset in a half turn,
#: whatever the tolerance. Leaving the band counts as an approach that did not do.
TURN_BAND = 3.0
TURN_MARGIN = 0.1
#: Each approach again ends twice as near as the previous one, down to the tolerance over this
#: (and never nearer than the controller's ``min_arrival_radius``).
MAX_REAPPROACH_DIVISOR = 16.0


class GoalArrival:
    """Decides, cycle after cycle, how a controller ends its approach to a goal (see the module).

    Thread contract: used by one controller in its RT thread; not thread-safe.
    """

    def __init__(self, min_arrival_radius: float = 0.0) -> None:
        """``min_arrival_radius`` (m): an approach again never aims nearer, where the
        controller's own dead band would hold it short (the path follower's distance PID
        ignores a centimetre)."""
        self.min_arrival_radius = float(min_arrival_radius)
        self._goal: tuple[float, float, float] | None = None
        self.reset()

    def reset(self) -> None:
        """Forget the turn, the creep and the approaches again (a new goal, a lost path)."""
        self.turning = False
        self.creeping = False
        #: The approach ends within the tolerance over this (1: the first approach).
        self.divisor = 1.0

    def decide(
        self,
        pose: tuple[float, float, float],
        goal: tuple[float, float, float],
        xy_tolerance: float,
        yaw_tolerance: float,
        can_reverse: bool,
        near_end: bool = True,
    ) -> tuple[str, float] | None:
        """``(TURN, yaw error)``, ``(ARRIVE, 0.0)``, ``(CREEP, speed along the heading)`` or
        None: approach as usual. ``near_end``: the robot is on the last part of its path (a
        path with cusps may pass near its goal earlier). A goal different from the last one
        starts afresh; a new path to the same goal does not (planners replan every cycle)."""
        goal = (float(goal[0]), float(goal[1]), float(goal[2]))
        if self._goal is None or max(
            abs(a - b) for a, b in zip(goal, self._goal, strict=True)
        ) > 1e-6:
            self._goal = goal
            self.reset()
        x, y, yaw = pose
        dx, dy = goal[0] - x, goal[1] - y
        dist = math.hypot(dx, dy)
        yaw_error = normalize_angle(goal[2] - yaw)
        along = dx * math.cos(yaw) + dy * math.sin(yaw)
        lateral = abs(-dx * math.sin(yaw) + dy * math.cos(yaw))
        creep_possible = lateral <= CREEP_LATERAL * xy_tolerance and (along >= 0.0 or can_reverse)

        if self.creeping:
            if dist <= xy_tolerance and (dist <= 0.5 * xy_tolerance or abs(along) <= CREEP_DONE):
                self.creeping, self.turning = False, True  # there: the turn's check below
            elif creep_possible:
                return CREEP, _creep_speed(along)
            else:
                self.creeping = False
                self._approach_again()
                return None
        if not near_end:
            self.turning = False
            return None
        arrival_radius = min(xy_tolerance,
                             max(xy_tolerance / self.divisor, self.min_arrival_radius))
        if dist <= arrival_radius or (
            self.turning and dist <= TURN_BAND * xy_tolerance + TURN_MARGIN
        ):
            self.turning = True
            if abs(yaw_error) > yaw_tolerance:
                return TURN, yaw_error
            if dist <= xy_tolerance:
                self.divisor = 1.0
                return ARRIVE, 0.0
            if creep_possible:
                self.creeping = True
                return CREEP, _creep_speed(along)
            self.turning = False
            self._approach_again()
            return None
        if self.turning:  # the turn left the band: an approach that did not do
            self.turning = False
            self._approach_again()
        return None

    @property
    def reapproach(self) -> bool:
        """Approaching again: turned at the goal, the robot was beyond its tolerance."""
        return self.divisor > 1.0

    def _approach_again(self) -> None:
        self.divisor = min(2.0 * self.divisor, MAX_REAPPROACH_DIVISOR)


def _creep_speed(along: float) -> float:
    return math.copysign(min(CREEP_SPEED, max(CREEP_MIN_SPEED, CREEP_GAIN * abs(along))), along)


def creep_command(speed: float, last: float, dt: float, limits) -> float:
    """The creep's ``speed`` within the robot's speeds, and changed from the ``last`` command
    within its acceleration (away from zero) or deceleration (towards zero) over ``dt``
    (:func:`~easynav.controllers.command_limits.limit_command`, the linear part)."""
    return limit_command(speed, 0.0, last, 0.0, dt, limits)[0]
