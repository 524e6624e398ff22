"""Scenario 1: a person steps out in front of the robot and stands there for a few seconds.

The robot drives east along y = 3.4 in the living room of the home world. When it comes within
1.3 m of a person standing 0.9 m beside its way, the person steps into its way (0.5 m/s), stands
there 4 s, then walks back into the kitchen. The planner replans every 5 s here (the simple
stack's 1 Hz sometimes steers round the person in time, which would leave the outcome to
chance): what keeps the robot off the person is the collision reflex of the recovery system.
Without a recovery system the same robot runs into the person (the control run), which shows
the scenario is a real test of the reflex.
"""

from __future__ import annotations

import pytest
from scenario_run import ScenarioRun, scenario_params, speed_up, world_file

pytestmark = [
    pytest.mark.slow,
    pytest.mark.ros,
    pytest.mark.timeout(240),
    # One scenario at a time (--dist loadgroup): each takes about a core at 2x real time.
    pytest.mark.xdist_group("easynav_scenarios"),
]

START = (4.8, 3.4, 0.0)
GOAL = (9.2, 3.4, 0.0)
CROSSER = {
    "name": "crosser",
    "radius": 0.25,
    "speed": 0.5,
    "start_distance": 1.3,
    "pause": 4.0,
    "waypoints": [[7.1, 4.3], [7.1, 3.4], [7.1, 5.6]],
}
STEP_OUT = 1.8  # s from the start of its walk until the person stands in the robot's way
#: Simple recovery: no topics, so nothing to subscribe; the diagnostic one publishes its reflex.
SLOW_PLANNER = {"planner_node.simple.freq": 0.2}
RECOVERIES = {
    "diagnostic": scenario_params(**SLOW_PLANNER),
    "simple": scenario_params(
        recovery=None,
        **SLOW_PLANNER,
        **{
            "recovery_node.recovery_manager.plugin": "easynav_simple_recovery/SimpleRecoveryManager"
        },
    ),
}


def _cross(tmp_path, params, until_end: bool = True) -> tuple[ScenarioRun, tuple[str, str], float]:
    world = world_file(tmp_path, "crossing", START, [CROSSER])
    with ScenarioRun(tmp_path / "run", world, params, speed_up=speed_up()) as run:
        run.wait_for_goal_manager()
        run.send_goals([GOAL])
        if until_end:
            end = run.wait_for_end(timeout=120.0)
        else:
            # A robot pushing against the person keeps it from walking on (it waits rather than
            # walk into the robot): stop at the first contact, or once its walk is long over.
            # The wall-clock budget covers 60 s simulated at the speed-up, with a minute to
            # spare for a playground that runs slower than that on a loaded machine.
            run.spin_until(
                lambda: run.monitor.collision_count > 0 or run.sim_time() > 60.0,
                timeout=60.0 / speed_up() + 60.0,
                what="a collision",
            )
            run.client.cancel()
            end = ("CANCELLED by the test", "")
    started = run.record["obstacles"][0]["started_at"]
    assert started is not None, "the robot never came by: the person did not step out"
    # The robot edge's smallest gap to anything while the person stepped out and stood there.
    gap = run.min_clearance_between(started, started + STEP_OUT + CROSSER["pause"])
    print(f"\nperson stepped out at t={started:.1f} s; smallest gap {gap:.3f} m; result {end}")
    return run, end, gap


@pytest.mark.parametrize("recovery", sorted(RECOVERIES))
def test_the_collision_reflex_brakes_before_a_person_stepping_out(tmp_path, recovery):
    run, (state, message), gap = _cross(tmp_path, RECOVERIES[recovery])
    # What a user sees: the robot stops short of the person, waits, then goes on.
    assert run.truth.collisions == [], run.truth.collisions
    assert run.monitor.collision_count == 0
    assert 0.05 < gap < 0.5, f"the person was not in the robot's way (gap {gap:.3f} m)"
    assert state == "NAVIGATION_FINISHED", message
    if recovery == "diagnostic":
        # (At start-up, before the first scan, it also brakes: "no valid point perception".)
        started = run.record["obstacles"][0]["started_at"]
        triggered = next(
            (
                d
                for d in run.monitor.diagnostics
                if d.hardware_id == "safety_reflex"
                and d.stamp >= started
                and "imminent collision" in d.message
            ),
            None,
        )
        assert triggered is not None, "no 'imminent collision' from the reflex on /diagnostics"
        print(f"reflex: {triggered.message} (t={triggered.stamp:.1f} s)")


def test_without_a_reflex_the_robot_touches_the_person(tmp_path):
    # The playground's own params: DummyRecoveryManager, no reflex.
    run, _end, _gap = _cross(
        tmp_path, scenario_params(recovery=None, **SLOW_PLANNER), until_end=False
    )
    assert [c["with"] for c in run.truth.collisions][:1] == ["crosser"], run.truth.collisions
