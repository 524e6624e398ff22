"""Configuration checks run on every configure, in any mode (stricter in safety mode): every
error names its parameter as node/name, and any error fails the whole configure."""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping
from dataclasses import fields

from easynav.core.robot import DEFAULT_ROBOT_LIMITS, RobotLimits
from easynav.system.safety.realtime import memlock_allowed, try_sched_fifo

SYSTEM = "system_node"
CONTROLLER = "controller_node"
SENSORS = "sensors_node"

Parameters = Mapping[str, Mapping[str, object]]
PermissionCheck = Callable[[], tuple[bool, str]]


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


class _Checker:
    """Collects error messages; one instance per :func:`configuration_errors` call."""

    def __init__(self, parameters: Parameters) -> None:
        self.parameters = parameters
        self.errors: list[str] = []

    def has(self, node: str, name: str) -> bool:
        return name in self.parameters.get(node, {})

    def value(self, node: str, name: str, default: object = None) -> object:
        return self.parameters.get(node, {}).get(name, default)

    def number(self, node: str, name: str, rule: str, unit: str = "") -> float | None:
        """The value when it is a finite number obeying ``rule`` (">0", ">=0", "<=0"), else None
        after recording an error. Absent parameters are not checked (None, no error)."""
        if not self.has(node, name):
            return None
        value = self.value(node, name)
        label = f"{node}/{name} = {value!r}"
        if not _is_number(value):
            self.errors.append(f"{label} is not a number")
            return None
        number = float(value)  # type: ignore[arg-type]
        if not math.isfinite(number):
            self.errors.append(f"{label} is not finite")
            return None
        ok = {">0": number > 0.0, ">=0": number >= 0.0, "<=0": number <= 0.0}[rule]
        if not ok:
            self.errors.append(f"{label}{unit} must be {rule.replace('0', ' 0')}")
            return None
        return number

    def boolean(self, node: str, name: str) -> bool | None:
        if not self.has(node, name):
            return None
        value = self.value(node, name)
        if not isinstance(value, bool):
            self.errors.append(f"{node}/{name} = {value!r} must be true or false")
            return None
        return value


def _robot_limits(check: _Checker) -> dict[str, float | None]:
    limits: dict[str, float | None] = {}
    for f in fields(RobotLimits):
        name = f"robot_limits.{f.name}"
        if f.name == "min_linear_vel":
            rule = "<=0"
        elif f.name.endswith("_vel"):
            rule = ">=0"
        else:  # accelerations and decelerations
            rule = ">0"
        if check.has(CONTROLLER, name):
            limits[f.name] = check.number(CONTROLLER, name, rule)
        else:
            limits[f.name] = DEFAULT_ROBOT_LIMITS[f.name]
    return limits


def _frequencies(check: _Checker, in_use: Collection[tuple[str, str]] | None) -> None:
    system_rt = check.number(SYSTEM, "rt_freq", ">0", " Hz")
    system_nort = check.number(SYSTEM, "freq", ">0", " Hz")
    cycles = {"rt_freq": (system_rt, "rt_freq"), "freq": (system_nort, "freq")}
    for node in sorted(check.parameters):
        for name in sorted(check.parameters[node]):
            if "." not in name:
                continue
            last = name.rsplit(".", 1)[1]
            if last not in cycles:
                continue
            if in_use is not None and (node, name) not in in_use:
                continue  # declared (a default every plugin has) but scheduling nothing
            value = check.number(node, name, ">0", " Hz")
            system_value, system_name = cycles[last]
            if value is not None and system_value is not None and value > system_value:
                check.errors.append(
                    f"{node}/{name} = {value:g} Hz exceeds {SYSTEM}/{system_name} = "
                    f"{system_value:g} Hz: a component cannot run faster than the cycle that "
                    "schedules it"
                )
    check.number(SYSTEM, "spin_time_rt", ">=0", " s")
    check.number(SYSTEM, "spin_time_nort", ">=0", " s")
    for name in sorted(check.parameters.get(SYSTEM, {})):
        if name.startswith("robot_geometry."):
            check.number(SYSTEM, name, ">=0", " m")


def _controller_period(check: _Checker, controller_rt_freq: float | None) -> tuple[float, str]:
    """The controller's period and the parameter it comes from (0 when unknown)."""
    types = check.value(CONTROLLER, "controller_types", [])
    alias = types[0] if isinstance(types, list | tuple) and len(types) == 1 else None
    name = f"{CONTROLLER}/{alias}.rt_freq" if alias else "the controller's rt_freq"
    if controller_rt_freq is None and alias is not None:
        value = check.value(CONTROLLER, f"{alias}.rt_freq", 10.0)
        controller_rt_freq = float(value) if _is_number(value) else None  # type: ignore[arg-type]
    if controller_rt_freq is None or not math.isfinite(controller_rt_freq):
        return 0.0, name
    if controller_rt_freq <= 0.0:
        return 0.0, name
    return 1.0 / controller_rt_freq, name


def configuration_errors(
    parameters: Parameters,
    controller_rt_freq: float | None = None,
    *,
    sched_fifo_trial: PermissionCheck = try_sched_fifo,
    memlock_check: PermissionCheck = memlock_allowed,
    frequencies_in_use: Collection[tuple[str, str]] | None = None,
) -> list[str]:
    """Every configuration error (the checks below), each naming its parameter (``node/name``).

    ``parameters``: the effective parameters of every EasyNav node, ``{node: {name: value}}``
    (e.g. ``{"controller_node": {"robot_limits.max_linear_vel": 0.6, ...}, "system_node":
    {...}}``); absent parameters are not checked (their defaults are valid), except the
    robot limits, which default as RobotLimits when comparing with ``safety.plc_limits``.
    ``controller_rt_freq``: the loaded controller's ``rt_freq`` (Hz); None derives it from
    ``controller_node``'s ``controller_types`` and ``<alias>.rt_freq`` (default 10).
    ``sched_fifo_trial`` (tried only in safety mode with ``use_real_time`` true) and
    ``memlock_check`` (only with ``safety.lock_memory``) return ``(ok, message)``; tests
    replace them. ``frequencies_in_use``: ``(node, "<plugin>.rt_freq|freq")`` of the
    frequencies the loaded plugins run at; when given, the frequency rule looks only at those
    (every plugin declares both, and a part it does not have schedules nothing); None checks
    every one (a params file alone).

    Checks, in any mode: robot limits finite with max_* >= 0, min_linear_vel <= 0,
    accelerations/decelerations > 0; system_node.rt_freq/freq and every ``<plugin>.rt_freq``/
    ``<plugin>.freq`` finite and > 0, and not above the system cycle's; spin times and
    robot_geometry.* finite and >= 0; cmd_timeout and cmd_vel_keepalive_period finite and
    >= 0; cmd_timeout (when > 0) longer than the controller's period; sensors_node.forget_time
    > 0; the safety.* numbers valid; robot limits within safety.plc_limits when given (> 0);
    RLIMIT_MEMLOCK with safety.lock_memory. In safety mode also: plc_limits, heartbeat.period,
    status.timeout, cmd_timeout and cmd_vel_keepalive_period > 0, use_real_time true and
    SCHED_FIFO allowed.

    Thread contract: the configuring thread (system_node's on_configure). Returns an empty list
    when the configuration is valid; never raises for bad values.
    """
    check = _Checker(parameters)
    limits = _robot_limits(check)
    _frequencies(check, frequencies_in_use)

    cmd_timeout = check.number(CONTROLLER, "cmd_timeout", ">=0", " s")
    keepalive = check.number(CONTROLLER, "cmd_vel_keepalive_period", ">=0", " s")
    if cmd_timeout is not None and cmd_timeout > 0.0:
        period, rt_freq_name = _controller_period(check, controller_rt_freq)
        if period > 0.0 and cmd_timeout <= period:
            check.errors.append(
                f"{CONTROLLER}/cmd_timeout = {cmd_timeout:g} s must be longer than the "
                f"controller's period ({rt_freq_name}: {period:g} s)"
            )
    check.number(SENSORS, "forget_time", ">0", " s")

    plc_linear = check.number(SYSTEM, "safety.plc_limits.max_linear_vel", ">=0", " m/s")
    plc_angular = check.number(SYSTEM, "safety.plc_limits.max_angular_vel", ">=0", " rad/s")
    heartbeat = check.number(SYSTEM, "safety.heartbeat.period", ">=0", " s")
    status_timeout = check.number(SYSTEM, "safety.status.timeout", ">=0", " s")
    check.number(SYSTEM, "safety.max_pose_age", ">=0", " s")
    factor = check.number(SYSTEM, "safety.rt_monitor.max_period_factor", ">0")
    if factor is not None and factor <= 1.0:
        check.errors.append(
            f"{SYSTEM}/safety.rt_monitor.max_period_factor = {factor:g} must be > 1 (every "
            "cycle would be late)"
        )
    if check.has(SYSTEM, "safety.rt_monitor.max_late_cycles"):
        late = check.value(SYSTEM, "safety.rt_monitor.max_late_cycles")
        if not (isinstance(late, int) and not isinstance(late, bool) and late >= 1):
            check.errors.append(
                f"{SYSTEM}/safety.rt_monitor.max_late_cycles = {late!r} must be an integer >= 1"
            )

    _plc_limits(check, limits, plc_linear, plc_angular)

    if check.boolean(SYSTEM, "safety.lock_memory"):
        ok, why = memlock_check()
        if not ok:
            check.errors.append(f"{SYSTEM}/safety.lock_memory is true, but {why}")

    if check.boolean(SYSTEM, "safety.mode"):
        required = [
            (SYSTEM, "safety.plc_limits.max_linear_vel", plc_linear),
            (SYSTEM, "safety.plc_limits.max_angular_vel", plc_angular),
            (SYSTEM, "safety.heartbeat.period", heartbeat),
            (SYSTEM, "safety.status.timeout", status_timeout),
            (CONTROLLER, "cmd_timeout", cmd_timeout),
            (CONTROLLER, "cmd_vel_keepalive_period", keepalive),
        ]
        for node, name, value in required:
            if not check.has(node, name):
                check.errors.append(f"{node}/{name} is required in safety mode (must be > 0)")
            elif value is not None and value <= 0.0:
                check.errors.append(
                    f"{node}/{name} = {value:g} must be > 0 in safety mode (0 disables it)"
                )
        use_real_time = check.boolean(SYSTEM, "use_real_time")
        if use_real_time is False:
            check.errors.append(
                f"{SYSTEM}/use_real_time = false: safety mode requires real-time scheduling"
            )
        elif use_real_time is None and not check.has(SYSTEM, "use_real_time"):
            use_real_time = True  # the default
        if use_real_time:
            ok, why = sched_fifo_trial()
            if not ok:
                check.errors.append(
                    f"{SYSTEM}/use_real_time: safety mode requires SCHED_FIFO, which is not "
                    f"allowed: {why}"
                )
    return check.errors


def _plc_limits(
    check: _Checker,
    limits: dict[str, float | None],
    plc_linear: float | None,
    plc_angular: float | None,
) -> None:
    """robot_limits may not exceed the limits declared for the safety channel (0: not given)."""
    plc = f"{SYSTEM}/safety.plc_limits"
    if plc_linear:
        forward = limits["max_linear_vel"]
        backward = limits["min_linear_vel"]
        if forward is not None and forward > plc_linear:
            check.errors.append(
                f"{CONTROLLER}/robot_limits.max_linear_vel = {forward:g} m/s exceeds "
                f"{plc}.max_linear_vel = {plc_linear:g} m/s (the safety channel's limit)"
            )
        if backward is not None and -backward > plc_linear:
            check.errors.append(
                f"{CONTROLLER}/robot_limits.min_linear_vel = {backward:g} m/s: its magnitude "
                f"exceeds {plc}.max_linear_vel = {plc_linear:g} m/s (the safety channel's limit)"
            )
    if plc_angular:
        angular = limits["max_angular_vel"]
        if angular is not None and angular > plc_angular:
            check.errors.append(
                f"{CONTROLLER}/robot_limits.max_angular_vel = {angular:g} rad/s exceeds "
                f"{plc}.max_angular_vel = {plc_angular:g} rad/s (the safety channel's limit)"
            )
