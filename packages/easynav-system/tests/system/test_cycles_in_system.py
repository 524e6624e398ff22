"""The cycles of a running EasyNav: the RT loop's trigger on new perceptions, the restart of a
component's schedule after a triggered run, and the ``easynav_navstate`` debug topic."""

from __future__ import annotations

import threading
import time

import pytest

from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros

SCAN_TOPIC = "/cycles_test_scan"


def slow_system(controller_rt_freq: float):
    """The Dummy system with a slow controller and a slower localizer (whose own scheduled runs
    also force the controller), and one laser on :data:`SCAN_TOPIC`."""
    return system_params(
        **{
            "controller_node.dummy.rt_freq": controller_rt_freq,
            # The command guard needs a timeout longer than the controller's period.
            "controller_node.cmd_timeout": 3.0 / controller_rt_freq,
            "localizer_node.dummy.rt_freq": 0.2,
            "sensors_node.sensors": ["laser1"],
            "sensors_node.laser1": {"topic": SCAN_TOPIC, "type": "sensor_msgs/msg/LaserScan"},
        }
    )


class RunRecorder:
    """Wraps controller_node.run_scheduled (RT thread): ``(node time, forced, controller ran)``
    for every RT cycle of the controller."""

    def __init__(self, rt) -> None:
        node = rt.system_node.controller_node
        original = node.run_scheduled
        self.calls: list[tuple[float, bool, bool]] = []
        self._lock = threading.Lock()

        def run_scheduled(rt: bool, force: bool = False):
            now = node.now_seconds()
            ran = original(rt, force)
            with self._lock:
                self.calls.append((now, force, bool(ran)))
            return ran

        node.run_scheduled = run_scheduled  # the RT cycle looks it up on the instance

    def runs(self) -> list[tuple[float, bool]]:
        """``(time, forced)`` of every run of the controller."""
        with self._lock:
            return [(t, forced) for t, forced, ran in self.calls if ran]


def scan_publisher(ros):
    from sensor_msgs.msg import LaserScan

    node = ros.create_node("cycles_test_laser")
    publisher = node.create_publisher(LaserScan, SCAN_TOPIC, 10)

    def publish() -> None:
        msg = LaserScan()
        msg.header.frame_id = "base_footprint"
        msg.header.stamp = node.get_clock().now().to_msg()
        msg.angle_min, msg.angle_increment = -0.1, 0.1
        msg.range_min, msg.range_max = 0.05, 10.0
        msg.ranges = [1.0, 1.0, 1.0]
        publisher.publish(msg)

    return publisher, publish


def test_new_perceptions_trigger_the_rt_components_at_once(ros, params_file, runtime_factory):
    # A 0.5 Hz controller: on its schedule alone it would run about once in the 2 s below.
    rt = runtime_factory(params_file(slow_system(0.5)))
    assert rt.start(), rt.error
    publisher, publish = scan_publisher(ros)
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)
    recorder = RunRecorder(rt)
    triggered_before = rt.rt_loop.triggered_cycles
    ros.spin_for(0.3)
    start = rt.system_node.controller_node.now_seconds()
    for _ in range(10):
        publish()
        ros.spin_for(0.2)
    forced = [t for t, f in recorder.runs() if f and t >= start]
    # Every scan runs the controller (one run per scan; two scans that arrive within one RT
    # cycle would make one run, hence the margin).
    assert len(forced) >= 7, recorder.runs()
    # The RT loop woke up for them instead of waiting for its next deadline.
    assert rt.rt_loop.triggered_cycles - triggered_before >= 1


def test_a_triggered_run_restarts_the_schedule(ros, params_file, runtime_factory):
    period = 0.5  # a 2 Hz controller
    rt = runtime_factory(params_file(slow_system(1.0 / period)))
    assert rt.start(), rt.error
    publisher, publish = scan_publisher(ros)
    assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, timeout=5.0)
    recorder = RunRecorder(rt)
    clock = rt.system_node.controller_node.now_seconds
    # Publish a scan halfway between two scheduled runs (tried again if the machine is slow).
    def scheduled_after(t0: float) -> list[float]:
        return [t for t, f in recorder.runs() if not f and t > t0]

    last_scheduled = -1.0
    for _attempt in range(10):
        assert ros.spin_until(lambda t0=last_scheduled: scheduled_after(t0), timeout=5.0)
        last_scheduled = max(scheduled_after(last_scheduled))
        halfway = last_scheduled + period / 2
        assert ros.spin_until(lambda t0=halfway: clock() >= t0, timeout=5.0)
        if clock() < halfway + 0.1:
            publish()
            break
    else:
        pytest.fail("could not publish between two scheduled runs")
    assert ros.spin_until(
        lambda: any(f for t, f in recorder.runs() if t > last_scheduled), timeout=5.0
    )
    triggered = min(t for t, f in recorder.runs() if f and t > last_scheduled)
    # The next scheduled run comes one period after the triggered run, not one period after
    # the last scheduled one (which would be at most period / 2 + 0.1 s after the trigger).
    assert ros.spin_until(
        lambda: any(not f and t > triggered for t, f in recorder.runs()), timeout=5.0
    )
    following = min(t for t, f in recorder.runs() if not f and t > triggered)
    # (The margin covers a preemption between the recorder's clock read and the schedule's.)
    assert following - triggered >= period - 0.05, recorder.runs()


def test_navstate_is_published_on_easynav_navstate(ros, params_file, runtime_factory):
    from std_msgs.msg import String

    rt = runtime_factory(params_file(system_params()))
    assert rt.start(), rt.error
    node = ros.create_node("navstate_listener")
    received: list[str] = []
    node.create_subscription(String, "easynav_navstate", lambda m: received.append(m.data), 10)
    assert ros.spin_until(lambda: len(received) >= 2, timeout=5.0)
    # One line per key, "key [type]: value", then the groups.
    text = received[-1]
    hash_line = f"configuration_hash [str]: '{rt.nav_state.get('configuration_hash')}'"
    assert hash_line in text.splitlines()
    assert "group diagnostics: " in text
    # Published from the non-RT cycle: it keeps coming while subscribed.
    count = len(received)
    end = time.monotonic() + 5.0
    while len(received) == count and time.monotonic() < end:
        ros.spin_for(0.05)
    assert len(received) > count
