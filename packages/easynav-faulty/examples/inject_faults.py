"""The Faulty plugins working normally, then misbehaving for good, without ROS.

    python packages/easynav-faulty/examples/inject_faults.py

Three plugins configured from a dict of parameters, as a params file would configure them:
a FaultyLocalizer that jumps 1 m after 3 updates, a FaultyPlanner whose path turns to NaN
after 2 and a FaultyController that commands an absurd velocity (``max_velocity``) after 3.
Each update's NavState output is printed, so the moment each fault starts is visible; what the
system does about it is the subject of the repository's tests/fault_injection.
"""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginContext
from easynav.core.robot import RobotLimits
from easynav.core.types import Goals, Header, Odometry, Path, Pose, PoseStamped, TwistStamped
from easynav.faulty import FaultyController, FaultyLocalizer, FaultyPlanner

PARAMS = {
    "localizer.x": 1.0, "localizer.y": 2.0, "localizer.fault": "jump",
    "localizer.fault_after": 3,
    "planner.fault": "nan", "planner.fault_after": 2,
    "controller.linear_vel": 0.2, "controller.fault": "max_velocity",
    "controller.fault_after": 3,
}


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def main() -> None:
    clock = Clock()
    context = PluginContext(parameters=DictParameters(PARAMS), namespace="example", now=clock,
                            robot_limits=lambda: RobotLimits(max_linear_vel=0.5))
    localizer, planner, controller = FaultyLocalizer(), FaultyPlanner(), FaultyController()
    for plugin, alias in ((localizer, "localizer"), (planner, "planner"),
                          (controller, "controller")):
        plugin.initialize(context, alias)

    nav_state = NavState()
    goal = PoseStamped(Header(0.0, "map"), Pose.from_xy_yaw(3.0, 2.0, 0.0))
    nav_state.set("goals", Goals(Header(0.0, "map"), [goal]))
    for update in range(1, 6):
        clock.t += 0.1
        localizer.update_rt(nav_state)
        planner.update(nav_state)
        controller.update_rt(nav_state)
        pose = nav_state.get("robot_pose", Odometry).pose
        path = nav_state.get("path", Path)
        twist = nav_state.get("cmd_vel", TwistStamped).twist
        print(f"update {update}: robot_pose ({pose.x:.2f}, {pose.y:.2f})  path of {len(path)} "
              f"poses, {'finite' if path.is_finite() else 'NOT FINITE'}  "
              f"cmd_vel vx {twist.vx:g} m/s")


if __name__ == "__main__":
    main()
