"""Test helpers: recorded system actions, a simulated clock, a tiny robot and NavState builders.

Everything here runs without ROS: plugins get ``PluginContext(parameters=DictParameters(...),
node=None)`` and a :class:`RecordingActions` as ``PluginServices(recovery_actions=...)``.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext, PluginServices, RecoveryActions
from easynav.core.robot import RobotGeometry, RobotLimits
from easynav.core.types import (
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
    Twist,
    TwistStamped,
)

TAKEOVER = "cmd_vel.proposal.takeover"
OVERRIDE = "cmd_vel.proposal.override"

_namespaces = itertools.count()


class Clock:
    """A node clock the test moves by hand (seconds)."""

    def __init__(self, t: float = 1000.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


class RecordingActions(RecoveryActions):
    """The recovery node's actions as the real one implements them for velocities (NavState
    proposals, which :func:`end_rt_cycle` consumes like controller_node), recording every call.
    """

    def __init__(self, nav_state: NavState) -> None:
        self.nav_state = nav_state
        self.calls: list[tuple[str, Any]] = []
        self.reconfigure_accepted = True
        self.restore_accepted = True
        self.hold = False

    def names(self) -> list[str]:
        return [name for name, _ in self.calls]

    def of(self, name: str) -> list[Any]:
        return [args for n, args in self.calls if n == name]

    def command_velocity(self, twist: Twist) -> None:
        self.calls.append(("command_velocity", twist))
        self.nav_state.set(TAKEOVER, twist)

    def override_velocity(self, twist: Twist) -> None:
        self.calls.append(("override_velocity", twist))
        self.nav_state.set(OVERRIDE, twist)

    def abort_mission(self, reason: str) -> None:
        self.calls.append(("abort_mission", reason))

    def hold_mission_progress(self, hold: bool) -> None:
        self.calls.append(("hold_mission_progress", hold))
        self.hold = hold

    def request_shutdown(self, reason: str) -> None:
        self.calls.append(("request_shutdown", reason))

    def request_reconfigure(self, changes, reason: str) -> bool:
        self.calls.append(("request_reconfigure", (list(changes), reason)))
        return self.reconfigure_accepted

    def request_restore_parameters(self, reason: str) -> bool:
        self.calls.append(("request_restore_parameters", reason))
        return self.restore_accepted


def end_rt_cycle(nav_state: NavState) -> tuple[Twist | None, Twist | None]:
    """What controller_node does after the recovery system: take (and erase) the proposals."""
    takeover = nav_state.get(TAKEOVER) if nav_state.has(TAKEOVER) else None
    override = nav_state.get(OVERRIDE) if nav_state.has(OVERRIDE) else None
    nav_state.erase(TAKEOVER)
    nav_state.erase(OVERRIDE)
    return takeover, override


def make_context(
    params: dict[str, Any] | None = None,
    clock: Clock | None = None,
    actions: RecoveryActions | None = None,
    geometry: RobotGeometry | None = None,
    namespace: str | None = None,
    limits: Any = None,
) -> PluginContext:
    """A plugin context without ROS, in a TF namespace of its own (isolated TF buffer).
    ``limits``: the robot limits in force, a RobotLimits or a callable returning them (the
    defaults when None)."""
    geometry = geometry or RobotGeometry()
    if limits is None:
        limits = RobotLimits()
    return PluginContext(
        robot_limits=limits if callable(limits) else (lambda: limits),
        parameters=DictParameters(params or {}),
        node=None,
        node_name="recovery_node",
        namespace=namespace if namespace is not None else f"recovery_test_{next(_namespaces)}",
        now=clock or Clock(),
        robot_geometry=lambda: geometry,
        services=PluginServices(recovery_actions=actions),
    )


def scan(
    points, frame: str = "base_footprint", stamp: float = 1000.0, valid: bool = True
) -> PointPerception:
    """A point perception from a list of (x, y, z)."""
    array = np.asarray(points, dtype=float).reshape(-1, 3)
    return PointPerception(array, frame, stamp, valid, True)


def set_pose(
    nav_state: NavState,
    x: float,
    y: float,
    yaw: float = 0.0,
    variance: float = 0.01,
    twist: Twist | None = None,
    stamp: float = 0.0,
) -> None:
    covariance = np.zeros((6, 6))
    covariance[0, 0] = covariance[1, 1] = variance
    nav_state.set(
        "robot_pose",
        Odometry(
            Header(stamp, "map"),
            "base_footprint",
            Pose.from_xy_yaw(x, y, yaw),
            covariance,
            twist or Twist(),
        ),
    )


def set_goal(nav_state: NavState, x: float = 5.0, y: float = 0.0) -> None:
    nav_state.set("goals", Goals(Header(0.0, "map"), [PoseStamped(Header(0.0, "map"), Pose(x, y))]))
    nav_state.set("navigation_state", "ACTIVE")


def clear_goal(nav_state: NavState) -> None:
    nav_state.set("goals", Goals(Header(0.0, "map"), []))
    nav_state.set("navigation_state", "IDLE")


def set_cmd(
    nav_state: NavState, vx: float = 0.0, wz: float = 0.0, vy: float = 0.0, stamp: float = 0.0
) -> None:
    nav_state.set("cmd_vel", TwistStamped(Header(stamp, "base_link"), Twist(vx=vx, vy=vy, wz=wz)))


def set_path(nav_state: NavState, n: int) -> None:
    points = np.array([[i * 0.1, 0.0] for i in range(n)]).reshape(-1, 2)
    nav_state.set("path", Path.from_xy_yaw(points))


@dataclass
class Robot:
    """A unicycle that executes the command selected like the velocity mux (no smoothing).

    ``held`` keeps it in place whatever it is told (a robot blocked by something unseen).
    """

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    held: bool = False
    executed: list[Twist] = field(default_factory=list)

    def execute(self, nav_state: NavState, dt: float, takeover, override) -> Twist:
        if override is not None:
            twist = override
        elif takeover is not None:
            twist = takeover
        elif nav_state.get_or("navigation_paused", False):
            twist = Twist()
        elif nav_state.has("cmd_vel"):
            twist = nav_state.get("cmd_vel").twist
        else:
            twist = Twist()
        self.executed.append(twist)
        if not self.held:
            self.x += twist.vx * math.cos(self.yaw) * dt
            self.y += twist.vx * math.sin(self.yaw) * dt
            self.yaw += twist.wz * dt
        moving = Twist() if self.held else Twist(vx=twist.vx, wz=twist.wz)
        variance = 0.01
        if nav_state.has("robot_pose"):
            variance = float(nav_state.get("robot_pose").pose_covariance[0, 0])
        set_pose(nav_state, self.x, self.y, self.yaw, variance, moving)
        return twist


class Sim:
    """A recovery manager cycled over simulated time: non-RT update, RT update, mux, robot."""

    def __init__(
        self,
        manager_cls,
        params: dict[str, Any],
        alias: str = "recovery_manager",
        geometry: RobotGeometry | None = None,
        robot: Robot | None = None,
    ) -> None:
        self.nav_state = NavState()
        self.clock = Clock()
        self.actions = RecordingActions(self.nav_state)
        self.context = make_context(
            {f"{alias}.{k}": v for k, v in params.items()}, self.clock, self.actions, geometry
        )
        self.manager = manager_cls()
        self.manager.initialize(self.context, alias)
        self.robot = robot or Robot()
        self.takeovers: list[Twist | None] = []
        self.overrides: list[Twist | None] = []
        set_pose(self.nav_state, self.robot.x, self.robot.y)

    @property
    def namespace(self) -> str:
        return self.context.namespace

    def step(self, dt: float = 0.05) -> tuple[Twist | None, Twist | None]:
        self.clock.t += dt
        self.manager.update(self.nav_state)
        self.manager.update_rt(self.nav_state)
        takeover, override = end_rt_cycle(self.nav_state)
        self.takeovers.append(takeover)
        self.overrides.append(override)
        self.robot.execute(self.nav_state, dt, takeover, override)
        return takeover, override

    def run(self, seconds: float, dt: float = 0.05, until=None) -> float:
        """Step for ``seconds`` of simulated time (or until ``until()``); the time it took."""
        start = self.clock.t
        for _ in range(int(round(seconds / dt))):
            self.step(dt)
            if until is not None and until():
                break
        return self.clock.t - start
