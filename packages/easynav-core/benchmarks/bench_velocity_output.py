"""Benchmark: cost per RT cycle of VelocityOutput.cycle (guard + mux + smoother + publication
decision), beside references measured in the same run.

Scenarios (200 Hz RT cycle, node clock advancing 5 ms per cycle):

* ``idle``: nothing proposed, at rest (the common case while no goal is active);
* ``driving``: a 30 Hz controller writing a new stamped command every ~6.7 cycles, the output
  ramping, a clear safety state;
* ``mixed``: driving plus recovery TAKEOVER/OVERRIDE bursts, pauses, protective stops, safely
  limited speed changes, NaN commands and keepalive republication.

References: an empty Python function taking the same seven arguments, and constructing one
``Twist`` — the floor of any per-cycle Python work. The ratio is scenario p50 / empty-call p50.
Only ROS-free logic is measured: converting to a ROS message and publishing are the node's.

    .venv/bin/python packages/easynav-core/benchmarks/bench_velocity_output.py [--cycles 50000]
"""

from __future__ import annotations

import argparse
import math
import random
import time
from collections.abc import Callable

import numpy as np

from easynav.core.benchmarking import BenchRow, add_json_option, percentiles, report
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, SafetyChannelState, Twist, TwistStamped
from easynav.core.velocity import VelocityOutput

PERIOD = 0.005
LIMITS = RobotLimits(0.6, -0.3, 1.0, 1.0, 1.0, 2.0, 2.0)
CLEAR = SafetyChannelState(valid=True, protective_stop=False, reason="")
STOP = SafetyChannelState(valid=True, protective_stop=True, reason="")
LIMITED = SafetyChannelState(
    valid=True,
    protective_stop=False,
    speed_limited=True,
    max_linear_vel=0.2,
    max_angular_vel=0.5,
    reason="",
)

Inputs = tuple[
    float, TwistStamped | None, Twist | None, Twist | None, bool, SafetyChannelState | None, bool
]


def scenario(name: str, cycles: int, seed: int = 1) -> list[Inputs]:
    """Pre-built inputs, so that building them is not measured."""
    rng = random.Random(seed)
    inputs: list[Inputs] = []
    command: TwistStamped | None = None
    for i in range(cycles):
        now = 1000.0 + i * PERIOD
        if name == "idle":
            inputs.append((now, None, None, None, False, None, False))
            continue
        if i % 20 == 0 or (i * 3) // 20 != ((i - 1) * 3) // 20:  # a 30 Hz controller
            vx = 0.5 * math.sin(i / 400.0)
            wz = 0.8 * math.cos(i / 300.0)
            if name == "mixed" and rng.random() < 0.01:
                vx = math.nan
            command = TwistStamped(Header(stamp=now), Twist(vx=vx, wz=wz))
        takeover = override = None
        paused = False
        safety = CLEAR
        inhibited = False
        if name == "mixed":
            phase = (i // 400) % 6
            if phase == 1:
                takeover = Twist(vx=-0.1)
            elif phase == 2 and i % 400 < 20:
                override = Twist()
            elif phase == 3:
                paused = True
            elif phase == 4:
                safety = STOP if i % 400 < 100 else LIMITED
            elif phase == 5:
                inhibited = i % 400 < 50
        inputs.append((now, command, takeover, override, paused, safety, inhibited))
    return inputs


def measure(call: Callable[..., object], inputs: list[Inputs]) -> np.ndarray:
    """Seconds per call, one sample per call, after a warm-up."""
    for args in inputs[:1000]:
        call(*args)
    samples = np.empty(len(inputs))
    clock = time.perf_counter_ns
    for i, args in enumerate(inputs):
        start = clock()
        call(*args)
        samples[i] = clock() - start
    return samples * 1e-9


def empty_call(now, cmd, takeover, override, paused, safety, inhibited) -> None:
    """Reference: a call that does nothing with the same arguments."""


def one_twist(now, cmd, takeover, override, paused, safety, inhibited) -> Twist:
    """Reference: constructing one Twist."""
    return Twist(0.1, 0.0, 0.0, 0.0, 0.0, 0.2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=50_000)
    add_json_option(parser)  # --json PATH: the rows as JSON (benchmark convention)
    args = parser.parse_args()

    idle = scenario("idle", args.cycles)
    empty_p50, empty_p99 = percentiles(measure(empty_call, idle) * 1e6, 50, 99)
    twist_p50, _ = percentiles(measure(one_twist, idle) * 1e6, 50, 99)
    print(f"{args.cycles} cycles per scenario; reference: an empty call with the same arguments\n")
    rows = [BenchRow("one Twist constructed, p50", twist_p50, "µs", "empty call p50", empty_p50)]
    for name, keepalive in [("idle", 0.0), ("driving", 0.0), ("mixed", 0.1)]:
        output = VelocityOutput(LIMITS, cmd_timeout=0.5, keepalive_period=keepalive)
        p50, p99 = percentiles(measure(output.cycle, scenario(name, args.cycles)) * 1e6, 50, 99)
        # Goal: a small share of the 5 ms RT period (the loop has sensors, controller and
        # publication to fit beside it): at most 2 % of the period at the median.
        rows.append(
            BenchRow(f"VelocityOutput.cycle {name}, p50", p50, "µs", "empty call p50", empty_p50,
                     goal="<= 100 µs (2 % of the 5 ms RT period)", met=p50 <= 100.0)
        )
        rows.append(
            BenchRow(f"VelocityOutput.cycle {name}, p99", p99, "µs", "empty call p99", empty_p99)
        )
    report(rows, args.json)


if __name__ == "__main__":
    main()
