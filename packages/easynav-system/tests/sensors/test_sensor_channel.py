"""SensorChannel alone: parameters, subscription, conversion, storing, new_data, expiry, status."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from sensor_test_helpers import make_cloud, make_imu, make_scan

from easynav.common.sensors import PointPerception
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters
from easynav.system.sensors import SensorChannel, SensorsConfigurationError, SensorsManager
from easynav.system.sensors.handlers import LaserScanHandler

LASER = {"laser.topic": "/scan", "laser.type": "sensor_msgs/LaserScan", "laser.group": "front"}


class FakeClock:
    def __init__(self, now: float = 100.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


def channel(params: dict = LASER, forget_time: float = 0.5, clock: FakeClock | None = None):
    clock = clock or FakeClock()
    made = SensorChannel.from_parameters(
        DictParameters(params), "laser", None, forget_time, clock
    )
    return made, clock


def test_from_parameters_reads_the_sensor_and_resolves_its_handler():
    laser, _ = channel()
    assert (laser.sensor_id, laser.topic, laser.group) == ("laser", "/scan", "front")
    assert laser.type_name == "sensor_msgs/msg/LaserScan"  # the handler's full type
    assert isinstance(laser.handler, LaserScanHandler) and laser.forget_time == 0.5
    assert laser.perception is None and laser.status(100.0) == "no_data"


@pytest.mark.parametrize(
    "params, parameter",
    [({"laser.type": "sensor_msgs/msg/LaserScan"}, "sensors_node.laser.topic"),
     ({"laser.topic": "/scan"}, "sensors_node.laser.type")],
)  # fmt: skip
def test_from_parameters_errors_name_the_parameter(params, parameter):
    with pytest.raises(SensorsConfigurationError) as info:
        channel(params)
    assert parameter in str(info.value)


def test_a_handler_failing_to_configure_is_a_configuration_error(monkeypatch):
    def broken(self, sensor_id, parameters, node):
        raise RuntimeError("no calibration file")

    monkeypatch.setattr(LaserScanHandler, "configure", broken)
    with pytest.raises(SensorsConfigurationError, match="sensors_node.laser: handler "
                       "LaserScanHandler failed to configure: RuntimeError"):  # fmt: skip
        channel()


def test_convert_then_store_counts_and_keeps_the_perception():
    laser, clock = channel()
    nav_state = NavState()
    perception = laser.convert(make_scan([1.0, 2.0], stamp=clock.now - 0.1))
    assert perception.valid and perception.new_data
    assert not nav_state.has("laser"), "convert does not write NavState"
    assert laser.store(nav_state, perception)
    assert nav_state.get("laser", PointPerception) is perception is laser.perception
    assert (laser.messages, laser.rejected, laser.delayed) == (1, 0, False)
    assert laser.status(clock.now) == "ok"


def test_old_data_is_converted_invalid_and_counted_as_delayed(caplog):
    laser, clock = channel()
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        perception = laser.convert(make_scan([1.0], stamp=clock.now - 0.8))
    assert not perception.valid and not perception.new_data
    assert "Sensor 'laser'" in caplog.text and "0.800 s old" in caplog.text
    laser.store(NavState(), perception)
    assert laser.delayed and laser.status(clock.now) == "stale"


def test_rejected_messages_are_counted_and_never_raise(caplog):
    laser, _ = channel()
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        assert laser.convert(make_imu()) is None  # the handler fails on a wrong message
    nav_state = NavState()
    nav_state.set("laser", "someone else's string")
    perception = laser.convert(make_scan([1.0], stamp=100.0))
    assert laser.store(nav_state, perception) is False
    assert laser.rejected == 2 and laser.messages == 0 and laser.perception is None
    assert "failed" in caplog.text


def test_a_plugin_handler_returning_ragged_points_is_rejected_not_raised(caplog):
    laser, _ = channel()

    class RaggedHandler:
        def to_perception(self, msg, sensor_id):
            return PointPerception(stamp=100.0, points=[[0.0, 1.0, 2.0], [3.0]])

    laser.handler = RaggedHandler()
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        assert laser.convert(make_scan([1.0], stamp=100.0)) is None
    assert laser.rejected == 1
    assert "RaggedHandler returned points that are not an array of numbers" in caplog.text


def test_end_new_data_and_expire_replace_the_perception_never_mutate_it():
    laser, clock = channel()
    nav_state = NavState()
    laser.store(nav_state, laser.convert(make_scan([1.0], stamp=clock.now)))
    held = nav_state.get("laser")
    laser.end_new_data(nav_state)
    current = nav_state.get("laser")
    assert current is not held and held.new_data and not current.new_data and current.valid
    assert laser.expire(nav_state, clock.now + 0.5) is False, "exactly forget_time: still valid"
    assert laser.status(clock.now + 0.6) == "stale", "stale before the RT cycle expires it"
    assert laser.expire(nav_state, clock.now + 0.6) is True
    assert not nav_state.get("laser").valid and current.valid
    assert laser.expire(nav_state, clock.now + 0.7) is False, "expired once"


def test_laser_points_reach_the_perception_finite_and_read_only():
    laser, clock = channel()
    perception = laser.convert(make_scan([1.0, math.nan], stamp=clock.now))
    assert perception.points.shape == (1, 3) and not perception.points.flags.writeable


def test_erase_removes_only_a_key_it_wrote():
    laser, clock = channel()
    nav_state = NavState()
    nav_state.set("laser", "not ours yet")
    laser.erase(nav_state)
    assert nav_state.has("laser"), "never written by the channel: left alone"
    nav_state.erase("laser")
    laser.store(nav_state, laser.convert(make_scan([1.0], stamp=clock.now)))
    laser.erase(nav_state)
    assert not nav_state.has("laser")


class FakeNode:
    def __init__(self) -> None:
        self.subscriptions: list[tuple] = []
        self.destroyed: list[object] = []

    def create_subscription(self, message_class, topic, callback, qos):
        self.subscriptions.append((message_class, topic, callback, qos))
        return object()

    def destroy_subscription(self, subscription):
        self.destroyed.append(subscription)


def test_subscribe_with_sensor_data_qos_and_unsubscribe():
    from rclpy.qos import ReliabilityPolicy
    from sensor_msgs.msg import LaserScan

    laser, _ = channel()
    node = FakeNode()
    laser.subscribe(node, print)
    message_class, topic, callback, qos = node.subscriptions[0]
    assert (message_class, topic, callback) == (LaserScan, "/scan", print)
    assert qos.reliability == ReliabilityPolicy.BEST_EFFORT and qos.depth == 5
    subscription = laser.subscription
    laser.unsubscribe(node)
    assert node.destroyed == [subscription] and laser.subscription is None
    laser.unsubscribe(node)  # twice: nothing left to destroy
    assert len(node.destroyed) == 1


def test_a_missing_message_package_names_the_type_parameter(monkeypatch):
    laser, _ = channel()

    def missing():
        raise ImportError("message package 'sensor_msgs' is not installed")

    monkeypatch.setattr(laser.handler, "message_class", missing)
    with pytest.raises(SensorsConfigurationError, match=r"sensors_node\.laser\.type = "
                       "'sensor_msgs/msg/LaserScan': message package"):  # fmt: skip
        laser.subscribe(FakeNode(), print)


def test_the_manager_exposes_its_channels_in_configuration_order():
    params = {"sensors": ["laser", "lidar"], "lidar.topic": "/points",
              "lidar.type": "sensor_msgs/msg/PointCloud2", **LASER}  # fmt: skip
    manager = SensorsManager()
    nav_state = NavState()
    clock = FakeClock()
    manager.configure(DictParameters(params), None, nav_state, clock=clock)
    manager.handle_message("lidar", make_cloud(np.ones((2, 3)), stamp=clock.now))
    assert manager.channel("lidar").messages == 1 and manager.channel("laser").messages == 0
    assert manager.sensor_status(clock.now) == {"laser": "no_data", "lidar": "ok"}
    with pytest.raises(KeyError, match="sensor 'sonar' is not configured"):
        manager.channel("sonar")
