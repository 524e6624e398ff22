"""A system started in a process where another ran before (tests, a restarted runtime) starts
with an empty transform tree: the earlier run's transforms are on another time line."""

from __future__ import annotations

import math

import numpy as np
import pytest
from rclpy.parameter import Parameter

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


SYSTEM_NODES = ("system_node", "controller_node", "localizer_node", "planner_node",
                "maps_manager_node", "sensors_node", "recovery_node")


def test_a_simulator_restarted_under_a_running_system_empties_its_transform_tree(
    params_file, runtime_factory, ros
):
    """The TF listener runs on system_node's simulated time (its RT companion node is named in
    no params file): when ``/clock`` goes back, the old run's dynamic transforms go and the new
    ones are what a lookup returns; the static ones stay (their publisher sends them once). On
    the system time it never saw the jump: every transform of the new run was refused as older
    than the window, and lookups gave the old run's pose. The age of ``odom → base_footprint``
    when served is measured on the same simulated clock."""
    import time

    from rosgraph_msgs.msg import Clock

    from easynav.system.tf import StaticTFBroadcaster, TFBroadcaster

    simulator = ros.create_node("simulator")
    clock = simulator.create_publisher(Clock, "/clock", 10)
    tf = TFBroadcaster(simulator)
    static = StaticTFBroadcaster(simulator)
    static.send_transform(TransformStamped(
        Header(0.0, "base_footprint"), "laser",
        Transform(np.array((0.2, 0.0, 0.3)), np.array((0.0, 0.0, 0.0, 1.0)))))
    origin = {"sim": 60.0, "mono": time.monotonic(), "x": 3.0}

    def tick() -> None:
        now = origin["sim"] + time.monotonic() - origin["mono"]
        msg = Clock()
        msg.clock.sec, msg.clock.nanosec = int(now), int((now % 1.0) * 1e9)
        clock.publish(msg)
        tf.send_transform(_odom_to_base(now, origin["x"]))

    simulator.create_timer(0.01, tick)
    path = params_file(system_params(**{f"{n}.use_sim_time": True for n in SYSTEM_NODES}))
    runtime = runtime_factory(path)
    assert runtime.start(), runtime.error
    node = runtime.system_node
    assert node.rt_io_node.get_parameter("use_sim_time").value is True
    buffer = get_tf_buffer("")

    def newest() -> tuple[float, float]:
        try:
            stamp, values = buffer.lookup_transform_values("odom", "base_footprint")
        except LookupError:  # just cleared, nothing new yet
            return math.nan, math.nan
        return stamp, values[0]

    assert ros.spin_until(lambda: newest()[0] > 60.5 and buffer.frame_exists("laser"))
    origin.update(sim=1.0, mono=time.monotonic(), x=0.5)  # the simulator restarted
    assert ros.spin_until(lambda: newest()[0] < 30.0, timeout=3.0), newest()
    assert newest()[1] == 0.5
    assert buffer.can_transform("odom", "laser")  # the static transform stayed
    median, _, _ = node.tf_listener.odometry_age.summary()
    assert -0.05 < median < 1.0  # seconds, simulated stamps against the simulated clock

    # use_sim_time switched off on system_node at run time: its companion follows (its clock
    # changes source: the dynamic transforms go, the static one stays).
    node.set_parameters([Parameter("use_sim_time", value=False)])
    assert node.rt_io_node.get_parameter("use_sim_time").value is False
    assert buffer.frame_exists("laser")
