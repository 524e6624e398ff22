"""Closed-loop harness for controller plugins without ROS: a unicycle, a clock, the limits."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Pose, TwistStamped

_namespaces = itertools.count()


class Clock:
    """A settable clock for the plugin context."""

    def __init__(self, t: float = 100.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


class Limits:
    """Limits that a test can change while the controller runs (like a runtime change)."""

    def __init__(self, limits: RobotLimits) -> None:
        self.value = limits

    def __call__(self) -> RobotLimits:
        return self.value


def make_plugin(cls, alias: str, params=None, limits=None, clock=None, node_params=None):
    """An initialised plugin of ``cls`` with ``<alias>.<name>`` parameters from ``params``."""
    values = {f"{alias}.rt_freq": 20.0}
    values.update({f"{alias}.{k}": v for k, v in (params or {}).items()})
    values.update(node_params or {})
    limits = limits if isinstance(limits, Limits) else Limits(limits or RobotLimits())
    context = PluginContext(
        parameters=DictParameters(values),
        namespace=f"controllers_closed_loop_{next(_namespaces)}",
        now=clock or Clock(),
        robot_limits=limits,
    )
    plugin = cls()
    plugin.initialize(context, alias)
    return plugin


def set_pose(nav_state: NavState, x: float, y: float, yaw: float) -> None:
    nav_state.set(
        "robot_pose", Odometry(Header(0.0, "map"), "base_footprint", Pose.from_xy_yaw(x, y, yaw))
    )


def set_path(nav_state: NavState, xy_yaw: np.ndarray) -> None:
    nav_state.set("path", Path.from_xy_yaw(np.asarray(xy_yaw), Header(0.0, "map")))


def straight_path() -> np.ndarray:
    xs = np.arange(0.0, 3.001, 0.05)
    return np.column_stack((xs, np.zeros_like(xs), np.zeros_like(xs)))


def curved_path() -> np.ndarray:
    """A quarter circle of radius 2 m from (0, 0) heading +x to (2, 2) heading +y."""
    th = np.linspace(-math.pi / 2, 0.0, 64)
    return np.column_stack((2.0 * np.cos(th), 2.0 + 2.0 * np.sin(th), th + math.pi / 2))


def distance_to_path(path: np.ndarray, x: float, y: float) -> float:
    """Distance from (x, y) to the polyline ``path``."""
    a, b = path[:-1, :2], path[1:, :2]
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", (x, y) - a, ab) / np.einsum("ij,ij->i", ab, ab), 0, 1)
    q = a + ab * t[:, None]
    return float(np.min(np.hypot(q[:, 0] - x, q[:, 1] - y)))


@dataclass
class Run:
    """What a closed-loop run did."""

    poses: list[tuple[float, float, float]] = field(default_factory=list)
    commands: list[tuple[float, float]] = field(default_factory=list)
    stamps: list[float] = field(default_factory=list)
    arrived: bool = False

    @property
    def final(self) -> tuple[float, float, float]:
        return self.poses[-1]


def run_closed_loop(
    plugin,
    nav_state: NavState,
    clock: Clock,
    start=(0.0, 0.0, 0.0),
    dt: float = 0.05,
    t_max: float = 60.0,
    arrived: Callable[[object], bool] = lambda p: p.state == "arrived",
    before_step: Callable[[NavState, tuple[float, float, float]], None] | None = None,
    hold: float = 0.5,
) -> Run:
    """Drive a unicycle with ``plugin`` until ``arrived(plugin)`` has held for ``hold`` seconds
    with zero commands (or ``t_max``)."""
    x, y, yaw = start
    run = Run()
    held = 0.0
    for _ in range(int(t_max / dt)):
        set_pose(nav_state, x, y, yaw)
        if before_step is not None:
            before_step(nav_state, (x, y, yaw))
        plugin.update_rt(nav_state)
        cmd = nav_state.get("cmd_vel", TwistStamped)
        v, w = cmd.twist.vx, cmd.twist.wz
        run.poses.append((x, y, yaw))
        run.commands.append((v, w))
        run.stamps.append(cmd.header.stamp)
        if arrived(plugin) and v == 0.0 and w == 0.0:
            held += dt
            if held >= hold:
                run.arrived = True
                break
        else:
            held = 0.0
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
        yaw += w * dt
        clock.t += dt
    return run


def assert_within_limits(run: Run, limits: RobotLimits, dt: float, allow_reverse=True) -> None:
    """Every command within the speeds, and each change within acceleration/deceleration."""
    eps = 1e-9
    low = limits.min_linear_vel if allow_reverse else 0.0
    last = (0.0, 0.0)
    for v, w in run.commands:
        assert low - eps <= v <= limits.max_linear_vel + eps, (v, limits)
        assert abs(w) <= limits.max_angular_vel + eps, (w, limits)
        for now, before, acc, dec in (
            (v, last[0], limits.max_linear_acc, limits.max_linear_decel),
            (w, last[1], limits.max_angular_acc, limits.max_angular_decel),
        ):
            rate = max(acc, dec)
            assert abs(now - before) <= rate * dt + 1e-6, (now, before, rate)
        last = (v, w)
