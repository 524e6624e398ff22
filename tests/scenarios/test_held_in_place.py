"""Scenario 2: the robot is held in place (wheels blocked) in the middle of a mission.

The diagnostic recovery of easynav-recovery's example (params/diagnostic_recovery.params.yaml,
unchanged): ControllerStuckEvaluator reports ERROR after 2 s of commands without progress; the
mitigations that accept it are tried by priority — AdvanceRecovery (10; fails once the episode
lasted 15 s), HumanAssistanceRecovery (1000; fails after its 30 s timeout), CancelMissionRecovery
(2000) — and the client gets the aborted mission with the diagnosis as the reason.
"""

from __future__ import annotations

import math

import pytest
from scenario_run import ScenarioRun, scenario_params, speed_up, world_file

pytestmark = [
    pytest.mark.slow,
    pytest.mark.ros,
    pytest.mark.timeout(300),
    # One scenario at a time (--dist loadgroup): each takes about a core at 2x real time.
    pytest.mark.xdist_group("easynav_scenarios"),
]

START = (5.6, 3.4, 0.0)
GOAL = (8.6, 3.4, 0.0)
STUCK_KEY = "diagnostics.recovery_manager.controller_stuck"
ESCALATION = ["advance", "human_assistance", "cancel_mission"]  # priorities 10, 1000, 2000


def _episodes(
    reports: list[tuple[float, str]], cleared: list[float], key: str
) -> list[list[tuple[float, str]]]:
    """The mitigations selected for ``key``, as ``(stamp, alias)``, split into episodes: one
    ends when a mitigation succeeded or the diagnosis was OK again (``cleared`` stamps), which
    makes every mitigation eligible again (arbitration rule 3).

    Raises AssertionError when, within an episode, a mitigation was selected after the previous
    one failed without coming later in priority order.
    """
    priority = {alias: i for i, alias in enumerate(ESCALATION)}
    events = [(t, "cleared", "") for t in cleared]
    for stamp, text in reports:
        words = text.split()
        if text.startswith("mitigation ") and key in words:
            events.append((stamp, words[2], words[1]))
    episodes: list[list[tuple[float, str]]] = [[]]
    for stamp, verb, alias in sorted(events):
        if verb == "selected":
            episode = episodes[-1]
            assert not episode or priority[alias] > priority[episode[-1][1]], (
                f"{alias} selected after {episode[-1][1]} for {key}: not in priority order"
            )
            episode.append((stamp, alias))
        elif verb in ("succeeded", "cleared") and episodes[-1]:
            episodes.append([])
    return [e for e in episodes if e]


def test_a_held_robot_is_diagnosed_stuck_and_the_mission_aborted_after_the_mitigations(
    tmp_path,
):
    world = world_file(tmp_path, "held", START)
    with ScenarioRun(tmp_path / "run", world, scenario_params(), speed_up=speed_up()) as run:
        run.wait_for_goal_manager()
        run.send_goals([GOAL])
        run.spin_until(
            lambda: math.dist(run.position(), START[:2]) > 0.4, 60.0, "the robot to drive off"
        )
        run.hold_robot(True)
        # Blocked wheels: the true speed drops to zero at once (no braking ramp).
        run.spin_until(lambda: run.monitor.speed == 0.0, 10.0, "the robot to be held")
        state, message = run.wait_for_end(timeout=2 * (2 + 15 + 30) / speed_up() + 60.0)
        # The last reports may follow the mission's end by a cycle.
        run.spin_until(
            lambda: (
                any(" cancel_mission selected " in m for m in run.monitor.report_messages())
                or state != "NAVIGATION_FAILED"
            ),
            10.0,
            "the last mitigation report",
        )
        ended_at = run.sim_time()
        reports = [(r.stamp, r.message) for r in run.monitor.reports]
        stuck_ok = [
            d.stamp
            for d in run.monitor.diagnostics
            if d.name.endswith("controller_stuck") and d.level == 0
        ]
    # When the playground blocked the wheels (its record), and where.
    held_at = run.record["holds"][0][0]
    held_pose = run.true_poses_between(held_at, held_at + 0.1)[0][1:]
    stuck = run.monitor.first_diagnostic("controller_stuck", level=2, since=held_at)

    # The client is told the mission failed, and why.
    assert state == "NAVIGATION_FAILED", (state, message)
    assert STUCK_KEY in message, message

    # The stuck diagnosis came ~2 s (stuck_time_threshold) after the wheels were blocked.
    assert stuck is not None, "no controller_stuck ERROR on /diagnostics"
    diagnosis_delay = stuck.stamp - held_at
    assert 1.5 < diagnosis_delay < 6.0, diagnosis_delay

    # The mitigations were tried in priority order, each after the previous one failed. (The
    # evaluator measures progress with EasyNav's pose estimate: when it wanders by more than
    # 5 cm, or jumps on a loaded machine, the diagnosis clears for a moment and a new episode
    # starts over; the last one goes all the way.)
    earlier = [(t, m) for t, m in reports if t < held_at]
    reports = [(t, m) for t, m in reports if t >= held_at]
    texts = "\n".join(f"{t:.2f} {m}" for t, m in reports)
    episodes = _episodes(reports, [t for t in stuck_ok if t >= held_at], STUCK_KEY)
    assert episodes and [alias for _, alias in episodes[-1]] == ESCALATION, texts
    for alias in ESCALATION[:2]:
        assert f"mitigation {alias} failed for {STUCK_KEY}" in texts, texts
    (t_advance, _), (t_human, _), (t_cancel, _) = episodes[-1]
    # AdvanceRecovery: escalate_after 15 s, unless its episode began before the hold (a start
    # within its episode_gap of an earlier attempt continues that episode).
    if len(episodes) == 1 and not any(" advance selected " in m for t, m in earlier):
        assert 14.0 < t_human - t_advance < 20.0
    assert 29.0 < t_cancel - t_human < 35.0  # HumanAssistanceRecovery: timeout 30 s

    # AdvanceRecovery commanded the robot forward at its 0.1 m/s, HumanAssistanceRecovery kept
    # it stopped; it did not move an inch. (The command in force is the last one the robot
    # took: the playground's record, in simulated time.)
    def command_at(stamp: float) -> float:
        return run.commands_applied(0.0, stamp)[-1][1]

    assert command_at(t_human - 0.5) == pytest.approx(0.1, abs=1e-6)
    assert command_at(t_cancel - 0.5) == 0.0
    moved = [math.dist((x, y), held_pose) for _, x, y in run.true_poses_between(held_at, ended_at)]
    assert moved and max(moved) < 0.01
    print(
        f"\nheld at t={held_at:.1f} s; stuck ERROR after {diagnosis_delay:.1f} s; advance "
        f"{t_human - t_advance:.1f} s, human assistance {t_cancel - t_human:.1f} s; aborted "
        f"{ended_at - held_at:.1f} s after the hold ({len(episodes)} episode(s)): {message}"
    )
