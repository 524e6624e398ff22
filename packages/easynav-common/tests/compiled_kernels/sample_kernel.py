"""A cached numba kernel hooked by compile_in_child, for the tests (imported by child processes
too, from this directory)."""

import numba

from easynav.common.compiled_kernels import compile_in_child


def _weighted_sum(values, weight):
    total = 0.0
    for i in range(values.shape[0]):
        total += values[i] * weight
    return total


weighted_sum = compile_in_child(numba.njit(cache=True)(_weighted_sum),
                                "sample_kernel:weighted_sum")
