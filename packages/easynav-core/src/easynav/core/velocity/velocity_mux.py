"""VelocityMux: selects, every RT cycle, the source that commands the robot."""

from __future__ import annotations

from easynav.core.types import Twist
from easynav.core.velocity.mux_selection import MuxSelection
from easynav.core.velocity.velocity_rules import (
    check_proposal_types,
    discard_non_finite,
    select_source,
)
from easynav.core.velocity.velocity_source import VelocitySource


def _copy(twist: Twist) -> Twist:
    return Twist(twist.vx, twist.vy, twist.vz, twist.wx, twist.wy, twist.wz)


class VelocityMux:
    """Picks the target velocity among the proposals of one RT cycle.

    Priority, highest first (the original EasyNav's mux order, with the safety channel's stop
    above everything, as a certified channel beside EasyNav requires):

    1. PROTECTIVE_STOP — the safety channel stops the robot (or its state is not valid): zero;
    2. MOTION_INHIBITED — the safety supervisor inhibits motion (old pose in safety mode): zero;
    3. OVERRIDE — a recovery emergency (e.g. braking);
    4. TAKEOVER — the recovery system drives the robot;
    5. PAUSE — navigation paused: zero;
    6. CONTROLLER — the controller plugin's command, only when it is a new one (the command
       guard decides that; pass None otherwise).

    Proposals last one cycle: a source that stops proposing leaves nothing behind except the
    target it set, which is kept while no source proposes (so the smoother keeps ramping towards
    it; the command guard's ``cmd_timeout`` replaces a kept non-zero target with zero, see
    :meth:`hold_zero`). A proposal with a NaN or infinite axis is discarded and reported in
    :attr:`MuxSelection.discarded`; the next valid source is used instead.

    The rules are :func:`velocity_rules.discard_non_finite` and
    :func:`velocity_rules.select_source`, the ones :func:`decide_velocity` applies (this class
    is their stateful view for a caller that wants the mux alone).

    Thread contract: owned by the RT thread (controller_node's publication step); not locked.
    ``reset`` is called from the lifecycle thread while the RT loop does not run.
    """

    def __init__(self) -> None:
        self._target = Twist()
        self._source = VelocitySource.NONE

    @property
    def target(self) -> Twist:
        """The target in force (kept across cycles without proposals). Do not modify it."""
        return self._target

    @property
    def source(self) -> VelocitySource:
        """Who set :attr:`target`."""
        return self._source

    def select(
        self,
        controller: Twist | None,
        takeover: Twist | None,
        override: Twist | None,
        paused: bool,
        protective_stop: bool,
        motion_inhibited: bool,
    ) -> MuxSelection:
        """Select this cycle's target.

        ``controller`` is the controller's command only when it is new (else None);
        ``takeover``/``override`` are the recovery system's proposals of this cycle (or None).
        Never raises on bad velocities: non-finite proposals are discarded and reported.
        Raises ``TypeError`` naming the source when a proposal is not a Twist.
        """
        check_proposal_types(controller, takeover, override)
        controller, takeover, override, discarded = discard_non_finite(
            controller, takeover, override
        )
        proposed = override is not None or takeover is not None or controller is not None
        choice = select_source(
            controller, takeover, override, paused, protective_stop, motion_inhibited
        )
        if choice is None:
            return MuxSelection(self._target, self._source, False, False, discarded)
        source, proposal = choice
        if proposal is None:
            self._set_zero(source)
        else:
            self._set(proposal, source)
        return MuxSelection(self._target, self._source, True, proposed, discarded)

    def hold_zero(self, source: VelocitySource) -> None:
        """Replace the kept target with zero, set by ``source`` (e.g. TIMEOUT, BRAKE)."""
        self._set_zero(source)

    def reset(self) -> None:
        """Forget the kept target (on activation): zero, source NONE."""
        self._set_zero(VelocitySource.NONE)

    def _set(self, twist: Twist, source: VelocitySource) -> None:
        # A copy: the proposer may modify its object after this cycle, the kept target must not.
        self._target = _copy(twist)
        self._source = source

    def _set_zero(self, source: VelocitySource) -> None:
        if not self._target.is_zero():
            self._target = Twist()
        self._source = source
