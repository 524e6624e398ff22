"""The SimpleRecoveryManager plugin reacting to two situations, without ROS.

    python packages/easynav-recovery/examples/simple_recovery.py

The plugin is configured from a dict of parameters (as ``recovery_node`` would from a params
file) and cycled at 20 Hz like the host cycles it: ``update`` (non-RT: diagnose and decide) then
``update_rt`` (RT: fast reactions). Its system actions (drive, brake, abort...) go to a small
:class:`RecoveryActions` here that prints them; a unicycle executes what wins: the OVERRIDE
(brake), else the TAKEOVER (a recovery manoeuvre), else the controller's ``cmd_vel``.

1. Obstacle ahead: the robot drives at 0.3 m/s towards a wall 2 m ahead; a laser sees it.
   The RT reflex brakes at ``robot_geometry.radius`` (0.3 m) + ``stop_distance`` (0.3 m).
2. Stuck: the robot is commanded forward but something unseen holds it. After ``stuck_time``
   the manager takes over and backs up for ``backup_time``, then lets the controller drive.
"""

from __future__ import annotations

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.core.nav_state import NavState
from easynav.core.plugins import (
    DictParameters,
    PluginContext,
    PluginServices,
    RecoveryActions,
)
from easynav.core.types import (
    Goals,
    Header,
    Odometry,
    Pose,
    PoseStamped,
    Twist,
    TwistStamped,
)
from easynav.recovery.simple import SimpleRecoveryManager

DT = 0.05
TAKEOVER = "cmd_vel.proposal.takeover"
OVERRIDE = "cmd_vel.proposal.override"


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


class PrintingActions(RecoveryActions):
    """What recovery_node does for the manager: velocities as NavState proposals, the rest
    printed (a real host aborts the mission, reconfigures, shuts down)."""

    def __init__(self, nav_state: NavState, clock: Clock) -> None:
        self.nav_state, self.clock = nav_state, clock

    def say(self, text: str) -> None:
        print(f"  t={self.clock.t:5.2f} s  {text}")

    def command_velocity(self, twist: Twist) -> None:
        self.nav_state.set(TAKEOVER, twist)

    def override_velocity(self, twist: Twist) -> None:
        self.nav_state.set(OVERRIDE, twist)

    def abort_mission(self, reason: str) -> None:
        self.say(f"abort mission: {reason}")

    def hold_mission_progress(self, hold: bool) -> None:
        self.say(f"hold mission progress: {hold}")

    def request_shutdown(self, reason: str) -> None:
        self.say(f"shutdown requested: {reason}")

    def request_reconfigure(self, changes, reason: str) -> bool:
        self.say(f"reconfigure {list(changes)}: {reason}")
        return True

    def request_restore_parameters(self, reason: str) -> bool:
        self.say(f"restore parameters: {reason}")
        return True


class World:
    """NavState, the clock, the manager and a unicycle robot on the x axis."""

    def __init__(self, params: dict, held: bool = False) -> None:
        self.nav_state, self.clock = NavState(), Clock()
        actions = PrintingActions(self.nav_state, self.clock)
        context = PluginContext(
            parameters=DictParameters({f"recovery_manager.{k}": v for k, v in params.items()}),
            node_name="recovery_node",
            namespace="example",
            now=self.clock,
            services=PluginServices(recovery_actions=actions),
        )
        self.manager = SimpleRecoveryManager()
        self.manager.initialize(context, "recovery_manager")
        self.x, self.held, self.source = 0.0, held, "controller"
        goal = PoseStamped(Header(0.0, "map"), Pose(5.0, 0.0))
        self.nav_state.set("goals", Goals(Header(0.0, "map"), [goal]))
        self.nav_state.set("navigation_state", "ACTIVE")
        self.set_pose(Twist())

    def set_pose(self, twist: Twist) -> None:
        covariance = np.diag([0.01, 0.01, 0.0, 0.0, 0.0, 0.01])
        self.nav_state.set("robot_pose", Odometry(Header(self.clock.t, "map"), "base_footprint",
                                                  Pose.from_xy_yaw(self.x, 0.0, 0.0),
                                                  covariance, twist))

    def step(self, controller_vx: float) -> Twist:
        """One cycle: the controller's command, the manager, the winner executed."""
        self.clock.t += DT
        self.nav_state.set("cmd_vel", TwistStamped(Header(self.clock.t, "base_footprint"),
                                                   Twist(vx=controller_vx)))
        self.manager.update(self.nav_state)
        self.manager.update_rt(self.nav_state)
        takeover = self.nav_state.get_or(TAKEOVER, None)
        override = self.nav_state.get_or(OVERRIDE, None)
        self.nav_state.erase(TAKEOVER)
        self.nav_state.erase(OVERRIDE)
        twist, source = (
            (override, "recovery OVERRIDE") if override is not None
            else (takeover, "recovery TAKEOVER") if takeover is not None
            else (Twist(vx=controller_vx), "controller")
        )
        if source != self.source:
            print(f"  t={self.clock.t:5.2f} s  x={self.x:.2f} m: {source} drives "
                  f"(vx {twist.vx:+.2f} m/s, wz {twist.wz:+.2f} rad/s), mitigation "
                  f"{self.manager.mitigation.value}")
            self.source = source
        if not self.held:
            self.x += twist.vx * DT
        self.set_pose(Twist() if self.held else twist)
        return twist


def obstacle_ahead() -> None:
    print("1. a wall 2 m ahead, controller commanding 0.3 m/s")
    world = World({"stop_distance": 0.3})
    wall_x = 2.0
    ys = np.linspace(-0.6, 0.6, 25)
    for _ in range(int(10.0 / DT)):
        # The laser (in base_footprint, 0.2 m up) sees the wall at its distance.
        points = np.column_stack((np.full_like(ys, wall_x - world.x), ys, np.full_like(ys, 0.2)))
        world.nav_state.set("laser", PointPerception(points, "base_footprint", world.clock.t))
        world.step(controller_vx=0.3)
    print(f"   stopped at x={world.x:.2f} m: {wall_x - world.x:.2f} m from the wall "
          f"(it brakes within radius 0.3 + stop_distance 0.3 = 0.6 m)")


def stuck() -> None:
    print("2. held in place while the controller commands 0.3 m/s")
    world = World({"stuck_time": 4.0, "backup_time": 1.5, "backup_speed": 0.1}, held=True)
    backed = 0.0
    for _ in range(int(8.0 / DT)):
        twist = world.step(controller_vx=0.3)
        backed += DT if twist.vx < 0 else 0.0
    print(f"   commanded backing up for {backed:.2f} s (backup_time 1.5 s), backup attempts "
          f"{world.manager.backup_attempts}")


def main() -> None:
    obstacle_ahead()
    stuck()


if __name__ == "__main__":
    main()
