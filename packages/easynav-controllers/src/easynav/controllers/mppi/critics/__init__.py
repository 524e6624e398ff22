"""The MPPI critics (one class per module) and their registry by name."""

from easynav.controllers.mppi.critics.constraint_critic import ConstraintCritic
from easynav.controllers.mppi.critics.cost_critic import CostCritic
from easynav.controllers.mppi.critics.goal_angle_critic import GoalAngleCritic
from easynav.controllers.mppi.critics.goal_critic import GoalCritic
from easynav.controllers.mppi.critics.path_align_critic import PathAlignCritic
from easynav.controllers.mppi.critics.path_angle_critic import PathAngleCritic
from easynav.controllers.mppi.critics.path_follow_critic import PathFollowCritic
from easynav.controllers.mppi.critics.prefer_forward_critic import PreferForwardCritic
from easynav.controllers.mppi.critics.twirling_critic import TwirlingCritic

#: Every critic by the name used in the controller's ``critics`` list.
CRITICS = {
    cls.NAME: cls
    for cls in (
        ConstraintCritic,
        CostCritic,
        GoalCritic,
        GoalAngleCritic,
        PathAlignCritic,
        PathFollowCritic,
        PathAngleCritic,
        PreferForwardCritic,
        TwirlingCritic,
    )
}

#: The default ``critics`` list: Nav2's default set without GoalAngleCritic. The controller
#: turns in place to the goal yaw once within the xy tolerance; GoalAngleCritic would turn a
#: forward-only robot to that yaw before it arrives, and it then circles round the goal
#: (reproduced between the tb3_sandbox pillars). GoalAngleCritic and TwirlingCritic are
#: available.
DEFAULT_CRITICS = [
    "ConstraintCritic",
    "CostCritic",
    "GoalCritic",
    "PathAlignCritic",
    "PathFollowCritic",
    "PathAngleCritic",
    "PreferForwardCritic",
]

__all__ = [
    "CRITICS",
    "DEFAULT_CRITICS",
    "ConstraintCritic",
    "CostCritic",
    "GoalAngleCritic",
    "GoalCritic",
    "PathAlignCritic",
    "PathAngleCritic",
    "PathFollowCritic",
    "PreferForwardCritic",
    "TwirlingCritic",
]
