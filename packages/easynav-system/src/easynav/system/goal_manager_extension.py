"""GoalManagerExtension: system_node's goal manager, kept across cleanup and configure."""

from __future__ import annotations

from easynav.system.goals.goal_manager import GoalManager
from easynav.system.goals.goal_manager_params import GoalManagerParams
from easynav.system.goals.goal_manager_ros import GoalManagerRos
from easynav.system.system_extension import SystemExtension


class GoalManagerExtension(SystemExtension):
    """Creates the goal manager at the first configure and keeps it: an ongoing mission
    survives a reconfiguration (cleanup → configure). Each configure applies the parameters
    again. Each non-RT cycle applies the recovery system's requests (abort, hold progress) and
    runs the manager (feedback, waypoints, FINISHED).

    Thread contract: ``configure`` in the configuring thread; ``cycle`` in the non-RT thread.
    """

    def __init__(self, system_node) -> None:
        self.node = system_node
        self.goal_manager: GoalManager | None = None
        self.ros: GoalManagerRos | None = None

    def configure(self) -> None:
        params = GoalManagerParams.declare(self.node.params)
        if self.goal_manager is None:
            self.goal_manager = GoalManager(
                self.node.nav_state, params, self.node.now_seconds, self.node.get_logger()
            )
            self.ros = GoalManagerRos(self.node, self.goal_manager)
            self.node.system.services.goal_manager = self.goal_manager
        else:
            self.goal_manager.set_params(params)

    def cycle(self) -> None:
        requests = self.node.requests
        for reason in requests.take_aborts():
            self.ros.abort_mission(reason)
        self.goal_manager.hold_mission_progress(requests.hold_progress)
        self.ros.update()
