"""configuration_errors: every configuration check (limits, frequencies, spin times, geometry,
command timeouts, PLC limits, safety mode's requirements), each error naming node/parameter."""

import math

import pytest

from easynav.system.safety import configuration_errors


def allowed():
    return True, "allowed"


def refused():
    return False, "not permitted (EPERM)"


def valid_parameters():
    return {
        "system_node": {
            "use_real_time": True,
            "rt_freq": 200.0,
            "freq": 200.0,
            "spin_time_rt": 0.001,
            "spin_time_nort": 0.001,
            "robot_geometry.radius": 0.3,
            "robot_geometry.inscribed_radius": 0.3,
            "robot_geometry.height": 0.5,
            "safety.mode": False,
            "safety.lock_memory": False,
            "safety.plc_limits.max_linear_vel": 0.0,
            "safety.plc_limits.max_angular_vel": 0.0,
            "safety.heartbeat.period": 0.0,
            "safety.rt_monitor.max_period_factor": 2.0,
            "safety.rt_monitor.max_late_cycles": 10,
            "safety.status.timeout": 0.0,
            "safety.max_pose_age": 1.0,
        },
        "controller_node": {
            "cmd_timeout": 0.5,
            "cmd_vel_keepalive_period": 0.0,
            "controller_types": ["ctrl"],
            "ctrl.plugin": "easynav_controller/DummyController",
            "ctrl.rt_freq": 30.0,
            "ctrl.freq": 10.0,
            "robot_limits.max_linear_vel": 0.6,
            "robot_limits.min_linear_vel": -0.3,
            "robot_limits.max_angular_vel": 1.0,
            "robot_limits.max_linear_acc": 1.0,
            "robot_limits.max_linear_decel": 1.0,
            "robot_limits.max_angular_acc": 2.0,
            "robot_limits.max_angular_decel": 2.0,
        },
        "localizer_node": {"loc.rt_freq": 50.0, "loc.freq": 5.0, "loc.reseed_freq": 0.1},
        "sensors_node": {"forget_time": 0.5},
    }


def safety_mode_parameters():
    params = valid_parameters()
    params["system_node"].update(
        {
            "safety.mode": True,
            "safety.plc_limits.max_linear_vel": 1.0,
            "safety.plc_limits.max_angular_vel": 2.0,
            "safety.heartbeat.period": 0.1,
            "safety.status.timeout": 0.2,
        }
    )
    params["controller_node"]["cmd_vel_keepalive_period"] = 0.1
    return params


def errors(params, rt_freq=30.0, fifo=allowed, memlock=allowed):
    return configuration_errors(params, rt_freq, sched_fifo_trial=fifo, memlock_check=memlock)


def with_value(node, name, value, base=valid_parameters):
    params = base()
    params[node][name] = value
    return params


def test_a_valid_configuration_has_no_errors():
    assert errors(valid_parameters()) == []
    assert errors(safety_mode_parameters()) == []


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("robot_limits.max_linear_vel", -0.1),
        ("robot_limits.max_angular_vel", math.inf),
        ("robot_limits.min_linear_vel", 0.1),
        ("robot_limits.max_linear_acc", 0.0),
        ("robot_limits.max_angular_decel", -1.0),
        ("robot_limits.max_linear_decel", math.nan),
        ("robot_limits.max_linear_vel", "fast"),
        ("cmd_timeout", -0.5),
        ("cmd_timeout", math.nan),
        ("cmd_vel_keepalive_period", -1.0),
        ("cmd_vel_keepalive_period", math.inf),
        ("ctrl.rt_freq", 0.0),
        ("ctrl.freq", math.nan),
    ],
)
def test_controller_node_errors_name_the_parameter(name, value):
    found = errors(with_value("controller_node", name, value))
    assert len(found) >= 1
    assert f"controller_node/{name} = {value!r}" in found[0]


@pytest.mark.parametrize(
    ("node", "name", "value"),
    [
        ("system_node", "rt_freq", 0.0),
        ("system_node", "freq", -5.0),
        ("system_node", "rt_freq", math.inf),
        ("system_node", "spin_time_rt", -0.001),
        ("system_node", "spin_time_nort", math.nan),
        ("system_node", "robot_geometry.radius", -0.3),
        ("system_node", "robot_geometry.height", math.inf),
        ("system_node", "safety.heartbeat.period", -1.0),
        ("system_node", "safety.status.timeout", math.nan),
        ("system_node", "safety.max_pose_age", -1.0),
        ("system_node", "safety.plc_limits.max_linear_vel", -1.0),
        ("system_node", "safety.rt_monitor.max_period_factor", 0.5),
        ("system_node", "safety.rt_monitor.max_late_cycles", 0),
        ("system_node", "safety.mode", "yes"),
        ("localizer_node", "loc.rt_freq", -1.0),
        ("sensors_node", "forget_time", 0.0),
    ],
)
def test_other_errors_name_the_parameter(node, name, value):
    found = errors(with_value(node, name, value))
    assert any(f"{node}/{name}" in e for e in found), found


def test_bool_is_not_a_number():
    assert "is not a number" in errors(with_value("system_node", "rt_freq", True))[0]


def test_a_plugin_faster_than_its_system_cycle_fails():
    found = errors(with_value("localizer_node", "loc.rt_freq", 300.0))
    assert found == [
        "localizer_node/loc.rt_freq = 300 Hz exceeds system_node/rt_freq = 200 Hz: a component "
        "cannot run faster than the cycle that schedules it"
    ]
    assert "system_node/freq" in errors(with_value("localizer_node", "loc.freq", 201.0))[0]


def test_only_frequencies_in_use_are_checked_when_known():
    params = valid_parameters()
    # A default every plugin declares, of a part the plugin does not have (or a plugin no
    # longer loaded): above the cycle's frequency, but it schedules nothing.
    params["controller_node"]["ctrl.freq"] = 500.0
    params["localizer_node"]["loc.rt_freq"] = 300.0
    in_use = {("controller_node", "ctrl.rt_freq"), ("localizer_node", "loc.freq")}
    found = configuration_errors(
        params, 30.0, sched_fifo_trial=allowed, memlock_check=allowed, frequencies_in_use=in_use
    )
    assert found == []
    in_use.add(("localizer_node", "loc.rt_freq"))
    found = configuration_errors(
        params, 30.0, sched_fifo_trial=allowed, memlock_check=allowed, frequencies_in_use=in_use
    )
    assert len(found) == 1 and "localizer_node/loc.rt_freq = 300 Hz exceeds" in found[0]
    # Without the set (a params file alone), every frequency is checked.
    assert len(errors(params)) == 2


def test_reseed_freq_and_similar_names_are_not_cycle_frequencies():
    assert errors(with_value("localizer_node", "loc.reseed_freq", 1000.0)) == []


def test_cmd_timeout_must_be_longer_than_the_controller_period():
    found = errors(with_value("controller_node", "cmd_timeout", 0.02), rt_freq=30.0)
    assert len(found) == 1
    assert "controller_node/cmd_timeout = 0.02 s must be longer" in found[0]
    assert "controller_node/ctrl.rt_freq" in found[0]
    # Derived from controller_types and <alias>.rt_freq when not given.
    params = with_value("controller_node", "cmd_timeout", 0.02)
    assert len(configuration_errors(params, None, sched_fifo_trial=allowed)) == 1
    # 0 disables the timeout: nothing to compare.
    assert errors(with_value("controller_node", "cmd_timeout", 0.0)) == []


@pytest.mark.parametrize(
    ("name", "value", "plc"),
    [
        ("robot_limits.max_linear_vel", 1.2, "safety.plc_limits.max_linear_vel"),
        ("robot_limits.min_linear_vel", -1.1, "safety.plc_limits.max_linear_vel"),
        ("robot_limits.max_angular_vel", 2.5, "safety.plc_limits.max_angular_vel"),
    ],
)
def test_robot_limits_may_not_exceed_the_plc_limits(name, value, plc):
    params = with_value("controller_node", name, value)
    params["system_node"]["safety.plc_limits.max_linear_vel"] = 1.0
    params["system_node"]["safety.plc_limits.max_angular_vel"] = 2.0
    found = errors(params)
    assert len(found) == 1
    assert f"controller_node/{name}" in found[0] and f"system_node/{plc}" in found[0]


def test_plc_limits_of_zero_are_not_given_outside_safety_mode():
    assert errors(with_value("controller_node", "robot_limits.max_linear_vel", 9.0)) == []


@pytest.mark.parametrize(
    ("node", "name"),
    [
        ("system_node", "safety.plc_limits.max_linear_vel"),
        ("system_node", "safety.plc_limits.max_angular_vel"),
        ("system_node", "safety.heartbeat.period"),
        ("system_node", "safety.status.timeout"),
        ("controller_node", "cmd_timeout"),
        ("controller_node", "cmd_vel_keepalive_period"),
    ],
)
def test_safety_mode_requires_each_setting(node, name):
    found = errors(with_value(node, name, 0.0, base=safety_mode_parameters))
    assert found == [f"{node}/{name} = 0 must be > 0 in safety mode (0 disables it)"]
    params = safety_mode_parameters()
    del params[node][name]
    assert errors(params) == [f"{node}/{name} is required in safety mode (must be > 0)"]


def test_safety_mode_requires_use_real_time_and_sched_fifo():
    found = errors(with_value("system_node", "use_real_time", False, base=safety_mode_parameters))
    assert found == ["system_node/use_real_time = false: safety mode requires real-time scheduling"]
    found = errors(safety_mode_parameters(), fifo=refused)
    assert len(found) == 1
    assert found[0].startswith("system_node/use_real_time: safety mode requires SCHED_FIFO")
    assert "EPERM" in found[0]


def test_sched_fifo_is_only_tried_in_safety_mode():
    tried = []

    def trial():
        tried.append(True)
        return False, "no"

    configuration_errors(valid_parameters(), 30.0, sched_fifo_trial=trial)
    assert tried == []


def test_lock_memory_fails_configure_when_not_allowed_in_any_mode():
    params = with_value("system_node", "safety.lock_memory", True)
    found = errors(params, memlock=lambda: (False, "RLIMIT_MEMLOCK is 8388608 bytes"))
    assert found == ["system_node/safety.lock_memory is true, but RLIMIT_MEMLOCK is 8388608 bytes"]
    assert errors(params) == []


def test_all_errors_are_reported_at_once():
    params = valid_parameters()
    params["controller_node"]["robot_limits.max_linear_vel"] = -1.0
    params["system_node"]["rt_freq"] = 0.0
    params["sensors_node"]["forget_time"] = -1.0
    assert len(errors(params)) == 3
