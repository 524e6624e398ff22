"""ParameterFreeze: the configuration frozen in safety mode."""

import math

import pytest

from easynav.system.safety import ParameterFreeze


def test_not_frozen_everything_is_accepted():
    freeze = ParameterFreeze()
    assert freeze.check_change("controller_node", "cmd_timeout", 0.5, 0.7) == (True, "")
    assert freeze.check_declare("controller_node", "x.y") == (True, "")
    assert freeze.check_reconfiguration() == (True, "")


def test_frozen_changes_are_rejected_naming_the_parameter():
    freeze = ParameterFreeze()
    freeze.freeze()
    ok, reason = freeze.check_change("controller_node", "ctrl.plugin", "a/A", "b/B")
    assert not ok
    assert reason.startswith("controller_node/ctrl.plugin: the configuration is frozen")
    assert "'a/A'" in reason and "'b/B'" in reason


@pytest.mark.parametrize(
    ("old", "new", "accepted"),
    [
        (0.5, 0.5, True),
        (math.nan, math.nan, True),
        ([1.0, 2.0], [1.0, 2.0], True),
        (["ctrl"], ("ctrl",), True),
        ("x", "x", True),
        (True, True, True),
        (1, 1.0, False),
        (1, True, False),
        ("1", 1, False),
        ([1.0], [1.0, 2.0], False),
        (0.5, 0.50001, False),
    ],
)
def test_frozen_same_value_is_still_accepted(old, new, accepted):
    freeze = ParameterFreeze()
    freeze.freeze()
    assert freeze.check_change("n", "p", old, new)[0] is accepted


def test_frozen_declarations_and_reconfiguration_are_refused():
    freeze = ParameterFreeze()
    freeze.freeze()
    ok, reason = freeze.check_declare("planner_node", "new.param")
    assert not ok and "planner_node/new.param" in reason and "while EasyNav configures" in reason
    ok, reason = freeze.check_reconfiguration("request_restore_parameters")
    assert not ok and reason.startswith("request_restore_parameters() refused")


def test_thawed_while_configuring_then_frozen_again():
    freeze = ParameterFreeze()
    freeze.freeze()
    with freeze.thawed():
        assert freeze.check_declare("n", "p")[0]
        assert freeze.check_change("n", "p", 1, 2)[0]
    assert freeze.frozen
    freeze.unfreeze()
    with freeze.thawed():
        pass
    assert not freeze.frozen
