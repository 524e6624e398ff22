"""VelocityMux: priority of sources, one-cycle proposals, non-finite proposals discarded."""

import math

import pytest

from easynav.core.types import Twist
from easynav.core.velocity import VelocityMux, VelocitySource

CTRL = Twist(vx=0.3)
TAKE = Twist(vx=0.1, wz=0.2)
OVER = Twist(vx=-0.05)


def select(mux, controller=None, takeover=None, override=None, paused=False, stop=False, inh=False):
    return mux.select(controller, takeover, override, paused, stop, inh)


@pytest.mark.parametrize(
    ("kwargs", "source", "target"),
    [
        (dict(controller=CTRL), VelocitySource.CONTROLLER, CTRL),
        (dict(controller=CTRL, paused=True), VelocitySource.PAUSE, Twist()),
        (dict(controller=CTRL, takeover=TAKE, paused=True), VelocitySource.TAKEOVER, TAKE),
        (dict(controller=CTRL, takeover=TAKE, override=OVER), VelocitySource.OVERRIDE, OVER),
        (dict(override=OVER, inh=True), VelocitySource.MOTION_INHIBITED, Twist()),
        (dict(override=OVER, inh=True, stop=True), VelocitySource.PROTECTIVE_STOP, Twist()),
    ],
)
def test_highest_priority_source_wins(kwargs, source, target):
    selection = select(VelocityMux(), **kwargs)
    assert selection.source is source
    assert selection.target == target
    assert selection.fresh


def test_without_new_proposal_the_last_target_is_kept():
    mux = VelocityMux()
    select(mux, controller=CTRL)
    selection = select(mux)
    assert selection.target == CTRL
    assert selection.source is VelocitySource.CONTROLLER
    assert not selection.fresh and not selection.proposed


def test_proposals_last_one_cycle_a_takeover_does_not_block_the_controller():
    mux = VelocityMux()
    select(mux, controller=CTRL, takeover=TAKE)
    selection = select(mux, controller=Twist(vx=0.2))
    assert selection.source is VelocitySource.CONTROLLER
    assert selection.target.vx == 0.2


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_proposals_are_discarded_and_the_next_valid_source_used(bad):
    mux = VelocityMux()
    selection = select(mux, controller=CTRL, override=Twist(wz=bad))
    assert selection.discarded == (VelocitySource.OVERRIDE,)
    assert selection.source is VelocitySource.CONTROLLER
    assert selection.proposed


def test_a_non_finite_controller_command_keeps_the_previous_target():
    mux = VelocityMux()
    select(mux, controller=CTRL)
    selection = select(mux, controller=Twist(vx=math.nan))
    assert selection.discarded == (VelocitySource.CONTROLLER,)
    assert selection.target == CTRL
    assert not selection.proposed


def test_proposals_during_a_stop_are_proposals_but_not_selected():
    selection = select(VelocityMux(), controller=CTRL, stop=True)
    assert selection.proposed
    assert selection.target == Twist()


def test_the_kept_target_is_a_copy_of_the_proposal():
    mux = VelocityMux()
    proposal = Twist(vx=0.3)
    select(mux, controller=proposal)
    proposal.vx = 5.0
    assert select(mux).target.vx == 0.3


def test_hold_zero_and_reset():
    mux = VelocityMux()
    select(mux, controller=CTRL)
    mux.hold_zero(VelocitySource.TIMEOUT)
    assert mux.target.is_zero() and mux.source is VelocitySource.TIMEOUT
    mux.reset()
    assert mux.source is VelocitySource.NONE
