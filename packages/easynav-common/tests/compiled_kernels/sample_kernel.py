"""A cached numba kernel hooked by compile_in_child, for the tests (imported by child processes
too, from this directory)."""

import os
import sys

import numba

from easynav.common.compiled_kernels import compile_in_child


def _weighted_sum(values, weight):
    total = 0.0
    for i in range(values.shape[0]):
        total += values[i] * weight
    return total


weighted_sum = compile_in_child(numba.njit(cache=True)(_weighted_sum),
                                "sample_kernel:weighted_sum")


# A child process (python -m easynav.common.compiled_kernels) that imports this module says at
# which scheduling policy it compiles, when a test asks for it.
if os.environ.get("EASYNAV_TEST_CHILD_POLICY_FILE") and getattr(
        sys.modules["__main__"].__spec__, "name", "") == "easynav.common.compiled_kernels":
    with open(os.environ["EASYNAV_TEST_CHILD_POLICY_FILE"], "a") as report:
        report.write(f"{os.sched_getscheduler(0)}\n")
