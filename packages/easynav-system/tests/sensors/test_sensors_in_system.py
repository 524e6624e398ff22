"""Sensors through a running EasyNav: sensors_node's subscriptions, RT loop, data age."""

from __future__ import annotations

import pytest
from sensor_test_helpers import make_scan

from easynav.common.sensors import PointPerception
from easynav.core.types import DiagnosticLevel
from easynav.system.testing.system_fixtures import system_params, wait_for

pytestmark = pytest.mark.ros

SENSORS = {
    "sensors_node.forget_time": 0.3,
    "sensors_node.sensors": ["laser1"],
    "sensors_node.laser1": {"topic": "/scan", "type": "sensor_msgs/msg/LaserScan"},
}


def perception(rt) -> PointPerception | None:
    return rt.nav_state.get_or("laser1", None)


def test_scans_reach_navstate_and_expire_when_the_driver_dies(ros, params_file, runtime_factory):
    rt = runtime_factory(params_file(system_params(**SENSORS)))
    assert rt.start(), rt.error
    driver = ros.create_node("laser_driver")
    from sensor_msgs.msg import LaserScan

    pub = driver.create_publisher(LaserScan, "/scan", 10)
    assert ros.spin_until(lambda: pub.get_subscription_count() > 0, timeout=10.0)

    def publish_for(seconds: float) -> None:
        end = driver.get_clock().now().nanoseconds * 1e-9 + seconds
        while (now := driver.get_clock().now().nanoseconds * 1e-9) < end:
            pub.publish(make_scan([1.0, 2.0, 3.0], stamp=now))
            ros.spin_for(0.02)

    publish_for(0.3)
    p = perception(rt)
    assert p is not None and p.valid and len(p) == 3
    assert wait_for(
        lambda: (
            rt.nav_state.get_or("diagnostics.sensors", None) is not None
            and rt.nav_state.get("diagnostics.sensors").level == DiagnosticLevel.OK
        )
    )
    # The driver dies: within forget_time (+ a cycle) the scan is no longer valid.
    assert wait_for(lambda: not perception(rt).valid, timeout=2.0)
    assert wait_for(
        lambda: rt.nav_state.get("diagnostics.sensors").level == DiagnosticLevel.WARN, timeout=2.0
    )
    assert rt.nav_state.get("diagnostics.sensors").values["stale"] == "laser1"
    # A delayed driver: data 1 s old on arrival is never used.
    stamp = driver.get_clock().now().nanoseconds * 1e-9 - 1.0
    pub.publish(make_scan([1.0], stamp=stamp))
    ros.spin_for(0.2)
    late = perception(rt)
    assert not late.valid
