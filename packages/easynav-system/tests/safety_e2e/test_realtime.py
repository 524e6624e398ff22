"""Timing (late RT cycles, SCHED_FIFO, memory locking with ``safety.lock_memory``): in safety
mode, too many late RT cycles stop ``easynav run`` with exit code 1 after braking; memory locking
and SCHED_FIFO are refused with a clear message where they are not permitted. These run
``easynav`` as a user does, in a subprocess (the test is the driver and the PLC).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from safety_e2e_harness import (
    HeartbeatReceiver,
    RobotDriver,
    SafetyPlc,
    assert_within_limits,
    easynav_process_env,
    full_speed,
    requires_sched_fifo,
    ros_context_after_start,
)
from safety_e2e_params import (
    ANGULAR_VEL,
    LIMITS,
    LINEAR_VEL,
    fault,
    safety_mode_system,
    system,
)

pytestmark = pytest.mark.ros

EASYNAV = str(Path(sys.executable).with_name("easynav"))

#: The permission tests run easynav as a normal user would: root dropping its capabilities and
#: limits with util-linux's setpriv and prlimit (which need root to do so).
as_normal_user = pytest.mark.skipif(
    os.geteuid() != 0 or not (shutil.which("setpriv") and shutil.which("prlimit")),
    reason="needs root and util-linux setpriv/prlimit to run easynav without CAP_SYS_NICE, "
    "CAP_IPC_LOCK and with finite RLIMIT_RTPRIO/RLIMIT_MEMLOCK",
)


class EasyNavProcess:
    """``easynav <args>`` in a subprocess; its output (stdout and stderr) collected by a thread
    so the test can keep spinning its executor meanwhile."""

    def __init__(self, args: list[str], prefix: list[str] | None = None) -> None:
        self.lines: list[str] = []
        self.process = subprocess.Popen(
            [*(prefix or []), EASYNAV, *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=easynav_process_env(),
        )
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in self.process.stdout:
            self.lines.append(line)

    @property
    def output(self) -> str:
        return "".join(self.lines)

    def exited(self) -> bool:
        return self.process.poll() is not None

    def wait_for_line(self, text: str, timeout: float = 20.0) -> None:
        end = time.monotonic() + timeout
        while not any(text in line for line in self.lines):
            assert time.monotonic() < end and not self.exited(), (
                f"'{text}' not printed:\n{self.output}"
            )
            time.sleep(0.02)

    def finish(self, timeout: float = 10.0) -> int:
        code = self.process.wait(timeout=timeout)
        self._reader.join(timeout=2.0)
        return code

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


@requires_sched_fifo
def test_late_rt_cycles_in_safety_mode_brake_and_exit_with_code_1(write_document):
    document = safety_mode_system(
        # A controller that blocks 100 ms in every update after driving for 3 s (time for the
        # test's nodes to discover the process): every RT cycle (5 ms) then starts late.
        **fault("hang", 150, hang_time=0.1),
        **{
            "system_node.safety.rt_monitor.max_period_factor": 2.0,
            "system_node.safety.rt_monitor.max_late_cycles": 3,
            "system_node.safety.lock_memory": True,
        },
    )
    easynav = EasyNavProcess(["run", write_document(document)])
    try:
        easynav.wait_for_line("EasyNav active")
        with ros_context_after_start() as ros:
            plc = SafetyPlc(ros)
            driver = RobotDriver(ros)
            heartbeats = HeartbeatReceiver(ros, deadline=0.1)
            assert ros.spin_until(
                lambda: driver.last_is(lambda t: full_speed(t, LINEAR_VEL, ANGULAR_VEL)),
                timeout=10.0,
            ), f"never drove: {driver.samples[-3:]}\n{easynav.output}"
            assert ros.spin_until(easynav.exited, timeout=10.0), easynav.output
            ros.spin_for(0.2)  # the last commands arrive
        code = easynav.finish()
    finally:
        easynav.kill()
    output = easynav.output
    assert code == 1, output
    assert "safety.lock_memory: process memory locked" in output
    assert "stopping EasyNav: 3 real-time cycles in a row started late (safety mode)" in output
    assert (
        "easynav: stopped: 3 real-time cycles in a row started late (safety mode) "
        "(exit code 1)" in output
    )
    # It braked from full speed, and its last command is an exact zero.
    last_moving = max(
        i for i, s in enumerate(driver.samples) if full_speed(s.twist, LINEAR_VEL, ANGULAR_VEL)
    )
    ramp = driver.samples[last_moving:]
    braking = [s for s in ramp if not s.twist.is_zero()]
    assert len(braking) > 2, f"stopped dead, not braked: {ramp[:5]}\n{output}"
    assert driver.last().as_tuple() == (0.0,) * 6
    assert_within_limits(ramp, LIMITS)
    # The heartbeat said so while it could, then its receiver's deadline fired.
    statuses = [(m.sequence, m.rt_status) for _, m in heartbeats.messages]
    assert any(status == 2 for _, status in statuses), statuses  # RT_ERROR
    assert heartbeats.events.deadline_missed
    assert plc.sent > 0


@as_normal_user
def test_without_permissions_safety_mode_and_memory_locking_are_refused_saying_how_to_grant_them(
    write_document,
):
    document = safety_mode_system(**{"system_node.safety.lock_memory": True})
    # No CAP_SYS_NICE / CAP_IPC_LOCK, RLIMIT_RTPRIO 0 and RLIMIT_MEMLOCK 8 MiB: a normal user.
    normal_user = [
        "setpriv",
        "--bounding-set",
        "-sys_nice,-ipc_lock",
        "prlimit",
        "--rtprio=0",
        f"--memlock={8 * 1024 * 1024}",
        "--",
    ]
    easynav = EasyNavProcess(["check", write_document(document)], prefix=normal_user)
    try:
        code = easynav.finish(timeout=30.0)
    finally:
        easynav.kill()
    output = easynav.output
    assert code == 2, output
    assert (
        "system_node/use_real_time: safety mode requires SCHED_FIFO, which is not allowed" in output
    )
    assert "LimitRTPRIO=99" in output and "ulimit -r" in output
    assert (
        "system_node/safety.lock_memory is true, but safety.lock_memory needs "
        "RLIMIT_MEMLOCK unlimited, but it is 8388608 bytes" in output
    )
    assert "LimitMEMLOCK=infinity" in output and "ulimit -l" in output


@as_normal_user
def test_without_sched_fifo_outside_safety_mode_easynav_runs_with_a_warning(write_document):
    easynav = EasyNavProcess(
        ["run", "--duration", "0.5", write_document(system())],
        prefix=["setpriv", "--bounding-set", "-sys_nice", "prlimit", "--rtprio=0", "--"],
    )
    try:
        code = easynav.finish(timeout=30.0)
    finally:
        easynav.kill()
    assert code == 0, easynav.output
    assert "easynav_rt: SCHED_FIFO priority 80 not permitted (EPERM)" in easynav.output


def test_rt_monitor_starts_over_after_an_activation(start_easynav):
    # Late means 20 periods (100 ms) here: a loaded test machine does not make cycles late,
    # but 0.3 s of inactivity would, were it counted.
    rt = start_easynav(
        system(
            **{
                "system_node.safety.rt_monitor.max_period_factor": 20.0,
                "system_node.safety.rt_monitor.max_late_cycles": 1,
            }
        )
    )
    node = rt.system_node
    node.trigger_deactivate()
    time.sleep(0.3)
    node.trigger_activate()
    time.sleep(0.2)
    assert rt.nav_state.get_or("diagnostics.rt_cycle", None) is None
    assert node.safety.rt_monitor.late_cycles == 0
    assert rt.requests.shutdown_reason is None
