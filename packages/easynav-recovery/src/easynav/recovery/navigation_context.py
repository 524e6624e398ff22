"""Small read-only questions about NavState that several recovery plugins ask.

Thread contract: any thread; values are read with ``get`` (writers replace objects, never mutate
them, so a reference read here stays consistent).
"""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.types import Goals, SafetyChannelState, Twist, TwistStamped
from easynav.recovery import nav_state_keys as keys


def has_active_goal(nav_state: NavState) -> bool:
    """True while a mission is under way: goals are present and the navigation is not IDLE."""
    if nav_state.has(keys.NAVIGATION_STATE):
        if nav_state.get(keys.NAVIGATION_STATE) != "ACTIVE":
            return False
    if not nav_state.has(keys.GOALS):
        return False
    goals = nav_state.get(keys.GOALS, Goals)
    return len(goals.goals) > 0


def navigation_paused(nav_state: NavState) -> bool:
    """True while a client has paused the navigation."""
    return bool(nav_state.get_or(keys.NAVIGATION_PAUSED, False))


def protective_stop(nav_state: NavState) -> bool:
    """True while the safety channel stops the robot (protective stop or no valid status)."""
    if not nav_state.has(keys.SAFETY_STATUS):
        return False
    return nav_state.get(keys.SAFETY_STATUS, SafetyChannelState).stops_robot


def commanded_velocity(nav_state: NavState, takeover: Twist | None = None) -> Twist | None:
    """The velocity about to be sent this RT cycle, as the velocity mux will choose it.

    ``takeover`` is the recovery system's own TAKEOVER proposal of this cycle (it may not be in
    NavState yet). Order, as the mux: an OVERRIDE already proposed this cycle, the TAKEOVER, zero
    while paused or in a protective stop, else the controller's last command (``cmd_vel``; the
    smoother keeps executing it even when it is not new). None when nothing was ever commanded.
    """
    if nav_state.has(keys.PROPOSAL_OVERRIDE):
        return nav_state.get(keys.PROPOSAL_OVERRIDE, Twist)
    if takeover is not None:
        return takeover
    if nav_state.has(keys.PROPOSAL_TAKEOVER):
        return nav_state.get(keys.PROPOSAL_TAKEOVER, Twist)
    if navigation_paused(nav_state) or protective_stop(nav_state):
        return Twist()
    if nav_state.has(keys.CMD_VEL):
        return nav_state.get(keys.CMD_VEL, TwistStamped).twist
    return None
