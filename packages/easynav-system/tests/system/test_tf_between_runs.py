"""A system started in a process where another ran before (tests, a restarted runtime) starts
with an empty transform tree: the earlier run's transforms are on another time line."""

from __future__ import annotations

import numpy as np
import pytest

from easynav.common.tf import get_tf_buffer
from easynav.core.types import Header, Transform, TransformStamped
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def _odom_to_base(stamp: float, x: float) -> TransformStamped:
    return TransformStamped(
        Header(stamp, "odom"), "base_footprint",
        Transform(np.array((x, 0.0, 0.0)), np.array((0.0, 0.0, 0.0, 1.0))),
    )


def test_a_new_system_does_not_see_the_transforms_of_the_one_before(
    params_file, runtime_factory
):
    path = params_file(system_params())
    first = runtime_factory(path)
    assert first.start(), first.error
    buffer = get_tf_buffer("")
    assert buffer.set_transform(_odom_to_base(60.0, 3.0), "first run")
    first.stop()

    second = runtime_factory(path)
    assert second.start(), second.error
    buffer = get_tf_buffer("")
    assert not buffer.frame_exists("base_footprint")
    # The new run's clock starts again near zero: its transforms are taken, and they are the
    # ones a lookup returns (with the old ones kept, this one was refused as "older than the
    # window" and a lookup gave the first run's pose).
    assert buffer.set_transform(_odom_to_base(1.0, 0.5), "second run")
    assert buffer.lookup_transform("odom", "base_footprint").transform.translation[0] == 0.5
