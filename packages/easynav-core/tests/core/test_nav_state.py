"""NavState: typed keys, groups, copies and concurrent access."""

import threading

import numpy as np
import pytest

from easynav.core.nav_state import NavState, NavStateKeyError, NavStateTypeError
from easynav.core.types import Header, Odometry, Pose, Twist, TwistStamped


def test_type_is_fixed_by_first_write_and_errors_name_both_types():
    ns = NavState()
    ns.set("robot_pose", Odometry())
    with pytest.raises(NavStateTypeError) as err:
        ns.set("robot_pose", Pose())
    assert "robot_pose" in str(err.value)
    assert "Odometry" in str(err.value) and "Pose" in str(err.value)
    with pytest.raises(NavStateTypeError):
        ns.get("robot_pose", Twist)


def test_missing_key_names_the_key():
    with pytest.raises(NavStateKeyError, match="'goals'"):
        NavState().get("goals")
    assert not NavState().has("goals")


def test_get_returns_the_object_and_get_safe_a_copy():
    ns = NavState()
    cmd = TwistStamped(Header(1.0, "base_link"), Twist(vx=0.3))
    ns.set("cmd_vel", cmd)
    assert ns.get("cmd_vel") is cmd
    copy = ns.get_safe("cmd_vel", TwistStamped)
    assert copy == cmd and copy is not cmd
    arr = np.arange(3.0)
    ns.set("arr", arr)
    safe = ns.get_safe("arr")
    safe[0] = 42
    assert ns.get("arr")[0] == 0


def test_groups_hide_keys_from_get_no_group():
    ns = NavState()
    ns.set("laser1", Pose(1.0))
    ns.set("laser2", Pose(2.0))
    ns.set("camera_depth", Pose(3.0))
    ns.set_group("front", ["laser2"])
    ns.add_to_group("front", "camera_depth")
    assert set(ns.get_no_group(Pose)) == {"laser1"}
    assert set(ns.get_by_type(Pose)) == {"laser1", "laser2", "camera_depth"}
    assert set(ns.get_group("front")) == {"laser2", "camera_depth"}
    assert ns.groups()["front"] == ("laser2", "camera_depth")
    assert "group front: laser2, camera_depth" in ns.debug_string()


def test_debug_string_uses_registered_printers():
    ns = NavState()
    ns.set("cmd_vel", TwistStamped(twist=Twist(vx=0.5)))
    ns.register_printer(TwistStamped, lambda t: f"vx={t.twist.vx}")
    assert "cmd_vel [TwistStamped]: vx=0.5" in ns.debug_string()


def test_concurrent_writers_and_readers_never_see_torn_or_mistyped_values():
    ns = NavState()
    ns.set("counter", 0)
    ns.set("pose", Pose())
    errors = []
    stop = threading.Event()

    def writer(offset: int) -> None:
        for i in range(20000):
            ns.set("pose", Pose(float(i + offset), float(i + offset)))
            ns.set(f"w{offset}", i)

    def reader() -> None:
        while not stop.is_set():
            try:
                p = ns.get_safe("pose", Pose)
                if p.x != p.y:
                    errors.append(p)
                ns.has("counter")
                ns.get_no_group(Pose)
                ns.keys()
            except Exception as exc:  # pragma: no cover - reported below
                errors.append(exc)

    threads = [threading.Thread(target=writer, args=(k * 100000,)) for k in range(3)]
    readers = [threading.Thread(target=reader) for _ in range(3)]
    for t in readers + threads:
        t.start()
    for t in threads:
        t.join()
    stop.set()
    for t in readers:
        t.join()
    assert errors == []
    assert ns.get("w0") == 19999 and ns.get("w200000") == 19999
