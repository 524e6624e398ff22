"""Helpers for the goal-manager tests without ROS: a settable clock, requests, robot poses."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.types import Goals, Header, Odometry, Pose, PoseStamped
from easynav.system.goals import GoalManager, GoalManagerParams, NavigationControl
from easynav.system.goals import NavigationControlType as T


class FakeClock:
    """A clock the test moves by hand (seconds)."""

    def __init__(self, start: float = 1000.0) -> None:
        self.t = start

    def __call__(self) -> float:
        return self.t

    def advance(self, dt: float) -> None:
        self.t += dt


def goal(x: float, y: float, yaw: float = 0.0, frame: str = "map") -> PoseStamped:
    return PoseStamped(header=Header(0.0, frame), pose=Pose.from_xy_yaw(x, y, yaw))


def goals_of(*poses: PoseStamped) -> Goals:
    return Goals(header=Header(0.0, "map"), goals=list(poses))


def control(kind: T, user: str, seq: int = 0, goals: Goals | None = None) -> NavigationControl:
    return NavigationControl(
        type=kind, header=Header(5.0, "map"), seq=seq, user_id=user, goals=goals or Goals()
    )


def request(user: str, *poses: PoseStamped, seq: int = 0) -> NavigationControl:
    return control(T.REQUEST, user, seq, goals_of(*poses))


def set_robot(nav_state: NavState, x: float, y: float, yaw: float = 0.0, z: float = 0.0) -> None:
    nav_state.set(
        "robot_pose",
        Odometry(header=Header(0.0, "map"), child_frame_id="base_footprint",
                 pose=Pose.from_xy_yaw(x, y, yaw, z)),
    )


def make_manager(**params) -> tuple[GoalManager, NavState, FakeClock]:
    nav_state = NavState()
    clock = FakeClock()
    manager = GoalManager(nav_state, GoalManagerParams(**params), clock)
    return manager, nav_state, clock
