"""SensorsManager without DDS: configuration, groups, data age, RT trigger, diagnostics."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from sensor_test_helpers import make_cloud, make_imu, make_scan

from easynav.common.sensors import (
    ImuPerception,
    PointPerception,
)
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters
from easynav.core.types import DiagnosticLevel, DiagnosticStatus
from easynav.system.sensors import PerceptionHandler, SensorsConfigurationError, SensorsManager
from easynav.system.sensors.handlers import LaserScanHandler


class FakeClock:
    def __init__(self, now: float = 100.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


def configured(params: dict, clock: FakeClock | None = None):
    nav_state = NavState()
    manager = SensorsManager()
    clock = clock or FakeClock()
    manager.configure(DictParameters(params), None, nav_state, clock=clock)
    return manager, nav_state, clock


TWO_LASERS = {
    "sensors": ["laser1", "laser2"],
    "laser1.topic": "/scan",
    "laser1.type": "sensor_msgs/msg/LaserScan",
    "laser2.topic": "/scan_rear",
    "laser2.type": "sensor_msgs/msg/LaserScan",
}


# -- configuration ----------------------------------------------------------------------------
@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, "soon"])
def test_forget_time_must_be_positive_and_finite(bad):
    with pytest.raises(SensorsConfigurationError, match=r"sensors_node\.forget_time"):
        configured({"forget_time": bad})


def test_defaults():
    manager, nav_state, _ = configured({})
    assert manager.forget_time == 1.0 and manager.sensor_ids == []


@pytest.mark.parametrize(
    "params, parameter, text",
    [
        ({"sensors": ["s"], "s.topic": "/x", "s.type": "sensor_msgs/msg/Temperature"},
         "sensors_node.s.type", "has no perception handler"),
        ({"sensors": ["s"], "s.topic": "/x"}, "sensors_node.s.type", "is not set"),
        ({"sensors": ["s"], "s.type": "sensor_msgs/msg/LaserScan"}, "sensors_node.s.topic",
         "is not set"),
        ({"sensors": ["s"], "s.topic": "/x", "s.plugin": "nobody/Handler"},
         "sensors_node.s.plugin", "unknown perception handler"),
        ({"sensors": ["s"], "s.topic": "/x", "s.type": "sensor_msgs/msg/Imu",
          "s.plugin": "easynav_sensors/LaserScanHandler"}, "sensors_node.s.type",
         "handles sensor_msgs/msg/LaserScan"),
        ({"sensors": ["a", "a"], "a.topic": "/x", "a.type": "sensor_msgs/msg/Imu"},
         "sensors_node.sensors", "more than once"),
        ({"sensors": "laser1"}, "sensors_node.sensors", r"must be a list \(str\[\]\)"),
        ({"sensors": ["a", ""]}, "sensors_node.sensors", "list of non-empty strings"),
    ],
)  # fmt: skip
def test_configuration_errors_name_the_parameter(params, parameter, text):
    with pytest.raises(SensorsConfigurationError, match=text) as info:
        configured(params)
    assert parameter in str(info.value)


def test_handler_chosen_by_type_or_plugin():
    manager, _, _ = configured(
        {
            "sensors": ["a", "b", "c"],
            "a.topic": "/a",
            "a.type": "sensor_msgs/LaserScan",  # short form accepted
            "b.topic": "/b",
            "b.plugin": "easynav_sensors/LaserScanHandler",  # type from the plugin
            "c.topic": "/c",
            "c.type": "vision_msgs/msg/Detection3DArray",
        }
    )
    assert isinstance(manager.handler("a"), LaserScanHandler)
    assert isinstance(manager.handler("b"), LaserScanHandler)
    assert type(manager.handler("c")).__name__ == "Detection3DArrayHandler"


# -- storing, groups --------------------------------------------------------------------------
def test_each_sensor_gets_its_own_key_and_groups_hide_it_from_get_no_group():
    params = dict(TWO_LASERS, **{"laser2.group": "rear"})
    manager, nav_state, clock = configured(params)
    manager.handle_message("laser1", make_scan([1.0] * 5, frame="laser_front", stamp=clock.now))
    manager.handle_message("laser2", make_scan([2.0] * 5, frame="laser_rear", stamp=clock.now))
    front = nav_state.get("laser1", PointPerception)
    assert front.frame_id == "laser_front" and len(front) == 5
    assert set(nav_state.get_no_group(PointPerception)) == {"laser1"}
    assert set(nav_state.get_group("rear")) == {"laser2"}
    assert set(nav_state.get_by_type(PointPerception)) == {"laser1", "laser2"}


def test_group_hides_a_sensor_even_before_its_first_message():
    manager, nav_state, _ = configured(dict(TWO_LASERS, **{"laser1.group": "front"}))
    assert nav_state.groups()["front"] == ("laser1",)


# -- RT trigger and new_data ----------------------------------------------------------------
def test_cycle_rt_reports_new_data_once_and_new_data_flag_follows():
    manager, nav_state, clock = configured(TWO_LASERS)
    assert manager.cycle_rt(clock.now) is False
    manager.handle_message("laser1", make_scan([1.0] * 3, stamp=clock.now))
    assert manager.has_new_data()
    assert manager.cycle_rt(clock.now) is True
    assert nav_state.get("laser1", PointPerception).new_data is True  # during this RT cycle
    assert not manager.has_new_data()
    assert manager.cycle_rt(clock.now + 0.005) is False
    assert nav_state.get("laser1", PointPerception).new_data is False
    assert nav_state.get("laser1", PointPerception).valid is True


# -- data age --------------------------------------------------------------------------------
def test_a_sensor_that_dies_stops_being_used():
    manager, nav_state, clock = configured(dict(TWO_LASERS, forget_time=0.5))
    manager.handle_message("laser1", make_scan([1.0] * 3, stamp=clock.now))
    manager.cycle_rt(clock.now)
    held = nav_state.get("laser1", PointPerception)  # a reader holding the old object
    clock.now += 0.4
    manager.cycle_rt(clock.now)
    assert nav_state.get("laser1", PointPerception).valid
    clock.now += 0.2  # 0.6 s old > forget_time
    manager.cycle_rt(clock.now)
    stale = nav_state.get("laser1", PointPerception)
    assert not stale.valid and not stale.new_data
    assert held.valid, "perceptions are replaced, never mutated under a reader"
    from easynav.common.sensors import PointPerceptionsOps

    assert PointPerceptionsOps(nav_state.get_no_group(PointPerception)).as_points().shape == (0, 3)


def test_a_delayed_driver_is_never_used(caplog):
    manager, nav_state, clock = configured(dict(TWO_LASERS, forget_time=0.5))
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("laser2", make_scan([1.0] * 3, stamp=clock.now - 0.8))
    stored = nav_state.get("laser2", PointPerception)
    assert not stored.valid and not stored.new_data
    assert manager.cycle_rt(clock.now) is False, "old data must not trigger the RT cycle"
    assert "Sensor 'laser2'" in caplog.text and "0.800 s old" in caplog.text


def test_data_stamped_in_the_future_is_not_used(caplog):
    manager, nav_state, clock = configured(dict(TWO_LASERS, forget_time=0.5))
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("laser1", make_scan([1.0] * 3, stamp=clock.now + 5.0))
    assert not nav_state.get("laser1", PointPerception).valid
    assert "in the future" in caplog.text


# -- diagnostics ------------------------------------------------------------------------------
def diagnostic(nav_state) -> DiagnosticStatus:
    return nav_state.get("diagnostics.sensors", DiagnosticStatus)


def test_diagnostics_list_no_data_and_stale_sensors_on_changes_only():
    manager, nav_state, clock = configured(dict(TWO_LASERS, forget_time=0.5))
    manager.cycle(clock.now)
    first = diagnostic(nav_state)
    assert first.level == DiagnosticLevel.WARN and first.hardware_id == "sensors_node"
    assert (
        first.values["no_data"] == "laser1, laser2" and "no data: laser1, laser2" in first.message
    )
    assert "diagnostics.sensors" in nav_state.get_group("diagnostics")
    manager.cycle(clock.now + 0.01)
    assert diagnostic(nav_state) is first, "unchanged status: not rewritten"

    manager.handle_message("laser1", make_scan([1.0], stamp=clock.now))
    manager.handle_message("laser2", make_scan([1.0], stamp=clock.now))
    manager.cycle_rt(clock.now)
    manager.cycle(clock.now)
    ok = diagnostic(nav_state)
    assert ok.level == DiagnosticLevel.OK and ok.message == "all sensors up to date"

    clock.now += 0.3
    manager.handle_message("laser2", make_scan([1.0], stamp=clock.now))
    clock.now += 0.3  # laser1 is 0.6 s old, laser2 0.3 s
    manager.cycle_rt(clock.now)
    manager.cycle(clock.now)
    warn = diagnostic(nav_state)
    assert warn.level == DiagnosticLevel.WARN and warn.values["stale"] == "laser1"
    assert warn.values["no_data"] == "" and "stale" in warn.message and "laser1" in warn.message


def test_no_sensors_is_ok():
    manager, nav_state, clock = configured({})
    manager.cycle(clock.now)
    assert diagnostic(nav_state).level == DiagnosticLevel.OK


# -- bad input --------------------------------------------------------------------------------
def test_malformed_cloud_is_a_warning_naming_the_sensor_and_nothing_is_stored(caplog):
    params = {"sensors": ["lidar"], "lidar.topic": "/points",
              "lidar.type": "sensor_msgs/msg/PointCloud2"}  # fmt: skip
    manager, nav_state, clock = configured(params)
    broken = make_cloud(np.ones((10, 3)), stamp=clock.now)
    broken.data = bytes(broken.data)[:7]
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("lidar", broken)
    assert "Sensor 'lidar': message rejected" in caplog.text and "7 bytes" in caplog.text
    assert not nav_state.has("lidar")
    manager.handle_message("lidar", make_cloud([[1, 2, 3], [math.nan, 0, 0]], stamp=clock.now))
    stored = nav_state.get("lidar", PointPerception)
    np.testing.assert_array_equal(stored.points, [[1, 2, 3]])


def test_nan_and_out_of_range_ranges_never_reach_a_consumer(caplog):
    manager, nav_state, clock = configured(TWO_LASERS)
    scan = make_scan([math.nan, math.inf, 0.01, 50.0, 1.0], stamp=clock.now)
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("laser1", scan)
    points = nav_state.get("laser1", PointPerception).points
    assert points.shape == (1, 3) and np.all(np.isfinite(points))
    assert "Sensor 'laser1'" in caplog.text and "dropped 3 of 5" in caplog.text


def test_a_failing_plugin_handler_does_not_stop_the_loop(caplog):
    manager, nav_state, clock = configured(TWO_LASERS)
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("laser1", make_imu())  # wrong message for the handler
    assert "Sensor 'laser1'" in caplog.text and "failed" in caplog.text
    assert not nav_state.has("laser1")


def test_a_key_taken_by_another_type_is_a_warning(caplog):
    manager, nav_state, clock = configured(TWO_LASERS)
    nav_state.set("laser1", "someone else's string")
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("laser1", make_scan([1.0], stamp=clock.now))
    assert "cannot store the perception" in caplog.text


# -- cleanup ----------------------------------------------------------------------------------
def test_cleanup_erases_keys_and_group_memberships():
    params = dict(TWO_LASERS, **{"laser2.group": "rear", "sensors": ["laser1", "laser2", "imu"],
                               "imu.topic": "/imu", "imu.type": "sensor_msgs/msg/Imu"})  # fmt: skip
    manager, nav_state, clock = configured(params)
    nav_state.add_to_group("rear", "other_key")
    manager.handle_message("laser1", make_scan([1.0], stamp=clock.now))
    manager.handle_message("laser2", make_scan([1.0], stamp=clock.now))
    manager.handle_message("imu", make_imu(stamp=clock.now))
    assert isinstance(nav_state.get("imu"), ImuPerception)
    manager.cleanup()
    assert not nav_state.has("laser1") and not nav_state.has("laser2") and not nav_state.has("imu")
    assert nav_state.groups()["rear"] == ("other_key",)
    manager.handle_message("laser1", make_scan([1.0], stamp=clock.now))  # late callback: ignored
    assert not nav_state.has("laser1")


# -- plugin handlers --------------------------------------------------------------------------
class RangeAsPointHandler(PerceptionHandler):
    """A third-party handler: sensor_msgs/Range -> one point ahead (NaN when out of range)."""

    ros_message_type = "sensor_msgs/msg/Range"
    perception_type = PointPerception

    def to_perception(self, msg, sensor_id):
        r = msg.range if msg.min_range <= msg.range <= msg.max_range else math.nan
        points = np.array([[r, 0.0, 0.0], [r, 0.1, 0.0]])
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        return PointPerception(points=points, frame_id=msg.header.frame_id, stamp=stamp)


@pytest.fixture
def range_plugin(monkeypatch):
    from easynav.system.sensors import handler_registry

    original = handler_registry.available_handlers

    def with_plugin():
        return dict(original(), **{"acme/RangeAsPointHandler": RangeAsPointHandler})

    monkeypatch.setattr(handler_registry, "available_handlers", with_plugin)


def range_msg(value: float, stamp: float):
    from sensor_msgs.msg import Range
    from sensor_test_helpers import ros_time

    msg = Range()
    msg.header.frame_id = "sonar"
    msg.header.stamp = ros_time(stamp)
    msg.min_range, msg.max_range, msg.range = 0.02, 4.0, value
    return msg


def test_plugin_handler_is_found_by_type_and_its_nan_points_never_reach_consumers(
    range_plugin, caplog
):
    params = {"sensors": ["sonar"], "sonar.topic": "/range", "sonar.type": "sensor_msgs/msg/Range"}
    manager, nav_state, clock = configured(params)
    assert isinstance(manager.handler("sonar"), RangeAsPointHandler)
    manager.handle_message("sonar", range_msg(1.5, clock.now))
    stored = nav_state.get("sonar", PointPerception)
    np.testing.assert_array_equal(stored.points, [[1.5, 0, 0], [1.5, 0.1, 0]])
    assert not stored.points.flags.writeable
    with caplog.at_level(logging.WARNING, logger="easynav.sensors"):
        manager.handle_message("sonar", range_msg(9.0, clock.now))
    assert nav_state.get("sonar", PointPerception).points.shape == (0, 3)
    assert "Sensor 'sonar': dropped 2 points with NaN/inf" in caplog.text


def test_plugin_handler_chosen_by_name(range_plugin):
    params = {"sensors": ["s"], "s.topic": "/r", "s.plugin": "acme/RangeAsPointHandler"}
    manager, _, _ = configured(params)
    assert isinstance(manager.handler("s"), RangeAsPointHandler)
