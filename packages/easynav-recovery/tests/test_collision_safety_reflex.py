"""CollisionSafetyReflex without ROS: stopping-distance box, closest approach, fail-safe."""

from __future__ import annotations

import numpy as np
import pytest
from recovery_harness import RecordingActions, make_context, scan

from easynav.core.nav_state import NavState
from easynav.core.plugins import PluginConfigurationError
from easynav.core.tf import get_tf_buffer
from easynav.core.types import DiagnosticLevel, Header, Transform, TransformStamped, Twist
from easynav.recovery.diagnostic.reflexes import CollisionSafetyReflex
from easynav.recovery.diagnostic.reflexes.collision_safety_reflex import first_collision

ALIAS = "recovery_manager.collision"


def make_reflex(params=None):
    nav_state = NavState()
    actions = RecordingActions(nav_state)
    context = make_context({f"{ALIAS}.{k}": v for k, v in (params or {}).items()}, None, actions)
    reflex = CollisionSafetyReflex()
    reflex.initialize(context, ALIAS)
    return reflex, nav_state, actions


def brakes(point, twist: Twist, params=None) -> bool:
    reflex, nav_state, actions = make_reflex(params)
    nav_state.set("laser1", scan([point]))
    triggered = reflex.check_and_mitigate(nav_state, twist)
    assert triggered == bool(actions.of("override_velocity"))
    return triggered


# Defaults: radius 0.3 + safety_margin 0.1 = 0.4; brake_acc 0.5 → at 0.5 m/s, 0.25 m to stop.
@pytest.mark.parametrize(
    ("point", "twist", "expected"),
    [
        ((0.6, 0.0, 0.2), Twist(vx=0.5), True),  # within 0.4 + 0.25 ahead
        ((0.7, 0.0, 0.2), Twist(vx=0.5), False),  # beyond the stopping distance
        ((0.6, 0.0, 0.2), Twist(vx=0.2), False),  # slower: 0.04 m to stop
        ((0.6, 0.35, 0.2), Twist(vx=0.5), True),  # its path sweeps the disc
        ((0.6, 0.45, 0.2), Twist(vx=0.5), False),  # beside the swept disc
        ((-0.6, 0.0, 0.2), Twist(vx=-0.5), True),  # backing into it
        ((-0.6, 0.0, 0.2), Twist(vx=0.5), False),  # behind, moving away
        ((0.0, 0.6, 0.2), Twist(vy=0.5), True),  # sideways (holonomic)
        ((0.6, 0.0, 0.7), Twist(vx=0.5), False),  # above robot_geometry.height
        ((0.35, 0.0, 0.2), Twist(wz=1.0), False),  # rotating in place is never braked
    ],
)
def test_brakes_exactly_for_points_it_would_hit_before_stopping(point, twist, expected):
    assert brakes(point, twist) is expected


def test_a_point_inside_the_disc_allows_moving_away_but_not_closer():
    assert not brakes((-0.2, 0.0, 0.2), Twist(vx=0.3))
    assert brakes((0.2, 0.0, 0.2), Twist(vx=0.3))


def test_the_safety_margin_widens_the_robot():
    point = (0.5, 0.45, 0.2)
    assert not brakes(point, Twist(vx=0.5))
    assert brakes(point, Twist(vx=0.5), {"safety_margin": 0.2})


def test_z_min_filter_ignores_the_ground():
    assert brakes((0.5, 0.0, 0.0), Twist(vx=0.5))
    assert not brakes((0.5, 0.0, 0.0), Twist(vx=0.5), {"z_min_filter": 0.05})


def test_turning_into_a_point_is_a_collision():
    # Going straight, the robot stops 0.403 m from the point: just clear of the 0.4 m disc.
    point = (0.6, 0.39, 0.2)
    assert not brakes(point, Twist(vx=0.5))
    assert brakes(point, Twist(vx=0.5, wz=0.5))  # turning towards it
    assert not brakes(point, Twist(vx=0.5, wz=-0.5))  # turning away


def test_fails_safe_without_a_valid_perception_but_lets_it_rotate():
    reflex, nav_state, actions = make_reflex()
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.2))
    assert "no valid point perception" in reflex.reason
    assert not reflex.check_and_mitigate(nav_state, Twist(wz=0.8))
    nav_state.set("laser1", scan([(0.5, 0.0, 0.2)], valid=False))  # expired data
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.2))
    assert actions.of("override_velocity") == [Twist(), Twist()]


def test_fails_safe_when_no_perception_can_be_transformed():
    reflex, nav_state, _ = make_reflex()
    nav_state.set("laser1", scan([(3.0, 0.0, 0.2)], frame="unknown_laser"))
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.2))
    assert "cannot be transformed" in reflex.reason or "can be transformed" in reflex.reason


def test_fuses_perceptions_of_other_frames():
    reflex, nav_state, _ = make_reflex()
    ts = TransformStamped(
        Header(0.0, "base_footprint"),
        "laser",
        Transform(np.array([0.2, 0.0, 0.2]), np.array([0.0, 0.0, 0.0, 1.0])),
    )
    get_tf_buffer(reflex.context.namespace).set_transform(ts, "test", is_static=True)
    nav_state.set("laser1", scan([(0.4, 0.0, 0.0)], frame="laser"))  # 0.6 m ahead
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.5))


def test_no_command_and_no_motion_are_not_checked():
    reflex, nav_state, _ = make_reflex()
    assert not reflex.check_and_mitigate(nav_state, None)
    assert not reflex.check_and_mitigate(nav_state, Twist())


def test_diagnostic_is_written_on_level_changes_only():
    reflex, nav_state, _ = make_reflex()
    key = f"diagnostics.{ALIAS}"
    nav_state.set("laser1", scan([(0.5, 0.0, 0.2)]))
    reflex.check_and_mitigate(nav_state, Twist(vx=0.0))
    first = nav_state.get(key)
    assert first.level == DiagnosticLevel.OK and first.hardware_id == "safety_reflex"
    reflex.check_and_mitigate(nav_state, Twist(vx=0.0))
    assert nav_state.get(key) is first  # not rewritten
    reflex.check_and_mitigate(nav_state, Twist(vx=0.5))
    warn = nav_state.get(key)
    assert warn.level == DiagnosticLevel.WARN and "imminent collision" in warn.message
    assert key in nav_state.groups()["diagnostics"]


def test_a_failing_check_stops_the_robot_and_reports_an_error(monkeypatch):
    reflex, nav_state, actions = make_reflex()

    def broken(nav_state, commanded):
        raise ValueError("boom")

    monkeypatch.setattr(reflex, "check", broken)
    assert reflex.check_and_mitigate(nav_state, Twist(vx=0.1))
    assert actions.of("override_velocity") == [Twist()]
    status = nav_state.get(f"diagnostics.{ALIAS}")
    assert status.level == DiagnosticLevel.ERROR and "boom" in status.message


def test_a_scan_is_fused_once_while_it_stays_the_same(monkeypatch):
    reflex, nav_state, _ = make_reflex()
    nav_state.set("laser1", scan([(2.0, 0.0, 0.2)]))
    first = reflex._cloud.update(nav_state, "base_footprint")
    assert reflex._cloud.update(nav_state, "base_footprint") is first
    nav_state.set("laser1", scan([(2.0, 0.0, 0.2)]))  # new data
    assert reflex._cloud.update(nav_state, "base_footprint") is not first


def test_downsampling_keeps_one_point_per_voxel():
    reflex, nav_state, _ = make_reflex({"downsample_leaf_size": 0.5})
    nav_state.set("laser1", scan([(2.01, 0.01, 0.2), (2.02, 0.02, 0.21), (3.0, 0.0, 0.2)]))
    assert reflex._cloud.update(nav_state, "base_footprint").shape == (2, 3)


@pytest.mark.parametrize("name", ["brake_acc", "downsample_leaf_size"])
def test_parameters_must_be_positive(name):
    with pytest.raises(PluginConfigurationError, match=f"{ALIAS}.{name}"):
        make_reflex({name: 0.0})


def test_first_collision_on_an_empty_cloud():
    assert first_collision(np.empty((0, 3)), 0.5, 0.0, 0.0, 0.4, 0.5) is None
