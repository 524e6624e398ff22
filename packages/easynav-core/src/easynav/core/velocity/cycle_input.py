"""CycleInput: everything one RT cycle's velocity decision depends on, frozen."""

from __future__ import annotations

from dataclasses import dataclass

from easynav.core.robot import RobotLimits
from easynav.core.types import SafetyChannelState, Twist, TwistStamped


@dataclass(frozen=True, slots=True)
class CycleInput:
    """The input of :func:`~easynav.core.velocity.velocity_decision.decide_velocity`.

    Built by the RT thread once per cycle from what the callbacks and the other loops handed
    over (NavState); the decision reads it and never modifies it (nor the objects it holds:
    do not modify them either while the decision runs).

    ``now``: node clock (s; simulated time with use_sim_time). ``controller``: NavState
    ``cmd_vel`` as it is this cycle (None when absent; the decision tells whether it is new).
    ``takeover`` / ``override``: the recovery system's proposals of this cycle (or None).
    ``paused``: NavState ``navigation_paused``. ``safety``: NavState ``safety_status`` (None
    when the safety channel's state is not read, ``safety.status.timeout`` = 0).
    ``motion_inhibited``: the safety supervisor's inhibition (old pose in safety mode).
    ``limits``: ``controller_node.robot_limits`` (deprecated per-controller limits already
    resolved into them at configuration), before any safety cut or speed zone.
    ``speed_zone``: NavState ``speed_limit`` (a fraction; None or outside (0, 1): no zone).
    ``cmd_timeout`` (s, 0: off), ``keepalive_period`` (s, 0: off) and ``max_dt`` (s, the largest
    ramp step) are controller_node's parameters.
    """

    now: float
    controller: TwistStamped | None
    takeover: Twist | None
    override: Twist | None
    paused: bool
    safety: SafetyChannelState | None
    motion_inhibited: bool
    limits: RobotLimits
    speed_zone: float | None = None
    cmd_timeout: float = 0.0
    keepalive_period: float = 0.0
    max_dt: float = 0.1
