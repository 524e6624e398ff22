"""Level-1 evaluators: they publish diagnostics, never actuate."""

from easynav.recovery.diagnostic.evaluators.amcl_convergence_evaluator import (
    AmclConvergenceEvaluator,
)
from easynav.recovery.diagnostic.evaluators.controller_stuck_evaluator import (
    ControllerStuckEvaluator,
)
from easynav.recovery.diagnostic.evaluators.no_path_evaluator import NoPathEvaluator
from easynav.recovery.diagnostic.evaluators.obstacle_too_close_evaluator import (
    ObstacleTooCloseEvaluator,
)
from easynav.recovery.diagnostic.evaluators.ros_graph_evaluator import RosGraphEvaluator
from easynav.recovery.diagnostic.evaluators.safety_channel_evaluator import (
    SafetyChannelEvaluator,
)

__all__ = [
    "AmclConvergenceEvaluator",
    "ControllerStuckEvaluator",
    "NoPathEvaluator",
    "ObstacleTooCloseEvaluator",
    "RosGraphEvaluator",
    "SafetyChannelEvaluator",
]
