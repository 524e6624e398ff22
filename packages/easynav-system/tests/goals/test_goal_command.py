"""``easynav goal``: follows a goal to its end over real topics, with the right exit code."""

from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest
from goal_test_helpers import goal, request, set_robot

from easynav.system.goals import GoalManagerParams
from easynav.system.goals.goal_client_state import GoalClientState as S
from easynav.system.goals.goal_command import goal_command

pytestmark = pytest.mark.ros


class CommandThread:
    """``goal_command`` in a thread of its own, sharing the test bed's context."""

    def __init__(self, bed, argv):
        self.out, self.err = io.StringIO(), io.StringIO()
        self.code = None
        self._thread = threading.Thread(
            target=lambda: setattr(self, "code", goal_command(
                argv, context=bed.context, out=self.out, err=self.err)),
            daemon=True,
        )
        self._thread.start()

    def done(self) -> bool:
        return not self._thread.is_alive()


def test_goal_followed_to_the_end_returns_zero(ros_bed):
    system = ros_bed.system(GoalManagerParams(update_frequency=50.0))
    set_robot(system.nav_state, 0.0, 0.0)
    command = CommandThread(ros_bed, ["1.5", "0.5", "0.3", "--timeout", "8"])
    assert ros_bed.spin_until(lambda: system.manager.is_active, timeout=5.0)
    goals = system.nav_state.get("goals").goals
    assert (goals[0].header.frame_id, goals[0].pose.x, goals[0].pose.y) == ("map", 1.5, 0.5)
    assert goals[0].pose.yaw == pytest.approx(0.3)
    ros_bed.spin_for(1.2)  # long enough for one progress line
    set_robot(system.nav_state, 1.5, 0.5, 0.3)
    assert ros_bed.spin_until(command.done, timeout=5.0)
    assert command.code == 0
    text = command.out.getvalue()
    assert "State: ACCEPTED_AND_NAVIGATING" in text
    assert "distance to goal    1.58 m" in text
    assert "Navigation finished in" in text


def test_rejected_goal_returns_one_with_the_reason(ros_bed):
    system = ros_bed.system(GoalManagerParams(allow_preempt_goal=False))
    system.manager.handle_control(request("someone_else", goal(9.0, 9.0)))
    command = CommandThread(ros_bed, ["1.0", "2.0"])
    assert ros_bed.spin_until(command.done, timeout=5.0)
    assert command.code == 1
    assert "NAVIGATION_REJECTED: Goal rejected; unable to preempt current active goal" in (
        command.err.getvalue()
    )


def test_timeout_cancels_the_goal_and_returns_four(ros_bed):
    system = ros_bed.system()
    set_robot(system.nav_state, 0.0, 0.0)
    command = CommandThread(ros_bed, ["3.0", "0.0", "--timeout", "0.5"])
    assert ros_bed.spin_until(command.done, timeout=5.0)
    assert command.code == 4
    assert "Goal cancelled (NAVIGATION_CANCELLED)" in command.out.getvalue()
    assert system.nav_state.get("navigation_state") == "IDLE"


def test_no_goal_manager_returns_three(ros_bed):
    ros_bed.system(namespace="elsewhere")
    command = CommandThread(ros_bed, ["1.0", "0.0", "--connect-timeout", "0.3"])
    assert ros_bed.spin_until(command.done, timeout=5.0)
    assert command.code == 3
    assert "no EasyNav goal manager found in namespace '/'" in command.err.getvalue()


def test_own_context_with_ros_arguments_and_nobody_listening(monkeypatch):
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    err = io.StringIO()
    argv = ["1", "2", "--connect-timeout", "0.2", "--ros-args", "-p", "use_sim_time:=false"]
    assert goal_command(argv, out=io.StringIO(), err=err) == 3
    assert "no EasyNav goal manager" in err.getvalue()


@pytest.mark.parametrize(
    ("argv", "message"),
    [(["one", "2"], "invalid float value"), (["nan", "2"], "x must be a finite number"),
     (["1", "2", "--timeout", "0"], "--timeout must be a positive"), ([], "required")],
)
def test_bad_arguments_return_two(argv, message, capsys):
    err = io.StringIO()
    assert goal_command(argv, err=err) == 2
    assert message in err.getvalue() + capsys.readouterr().err


_CTRL_C_SCRIPT = textwrap.dedent(
    """
    import sys, threading, time
    sys.path.insert(0, {helpers!r})
    from goal_ros_helpers import RosTestbed
    from goal_test_helpers import set_robot
    from easynav.system.goals.goal_command import goal_command

    bed = RosTestbed()
    system = bed.system()
    set_robot(system.nav_state, 0.0, 0.0)
    stop = threading.Event()
    def loop():
        while not stop.is_set():
            bed.spin_until(lambda: stop.is_set(), timeout=0.05)
    spinner = threading.Thread(target=loop)
    spinner.start()
    code = goal_command(["4.0", "0.0"], context=bed.context)
    stop.set()
    spinner.join()
    print("EXIT", code, system.nav_state.get("navigation_state"), flush=True)
    bed.close()
    """
)


def test_ctrl_c_cancels_the_goal(tmp_path):
    script = tmp_path / "ctrl_c.py"
    script.write_text(_CTRL_C_SCRIPT.format(helpers=os.path.dirname(__file__)))
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="OFF")
    proc = subprocess.Popen(
        [sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, env=env,
    )
    try:
        deadline = time.monotonic() + 30.0
        lines = []
        while time.monotonic() < deadline:
            line = proc.stdout.readline()
            lines.append(line)
            if S.ACCEPTED_AND_NAVIGATING.name in line or not line:
                break
        assert any(S.ACCEPTED_AND_NAVIGATING.name in line for line in lines), lines
        proc.send_signal(signal.SIGINT)
        rest, errors = proc.communicate(timeout=30.0)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert "Interrupted: cancelling the goal" in rest
    assert "Goal cancelled (NAVIGATION_CANCELLED)" in rest
    assert "EXIT 130 IDLE" in rest, errors
