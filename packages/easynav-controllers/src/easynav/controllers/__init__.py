"""EasyNav controllers: SimpleController (carrot following with PIDs), MPC, SeReST and VFF.

The algorithms (:class:`SimplePathFollower`, :class:`PIDController`, :class:`MPCOptimizer`,
:class:`SerestTracker`, :class:`VffVectors`) are plain Python/numpy (scipy for the MPC's
solver, imported when solving); the plugins (``easynav.controllers.*_controller``) are not
imported here.
"""

from easynav.controllers.mpc_optimizer import MPCOptimizer
from easynav.controllers.path_follower import (
    ARRIVED,
    CREEPING_TO_GOAL,
    FINAL_ROTATION,
    FOLLOWING,
    NO_PATH,
    SimplePathFollower,
    carrot_on_path,
)
from easynav.controllers.pid_controller import PIDController
from easynav.controllers.serest_tracker import SerestTracker
from easynav.controllers.vff_vectors import VffVectors

__all__ = [
    "ARRIVED",
    "CREEPING_TO_GOAL",
    "FINAL_ROTATION",
    "FOLLOWING",
    "NO_PATH",
    "MPCOptimizer",
    "PIDController",
    "SerestTracker",
    "SimplePathFollower",
    "VffVectors",
    "carrot_on_path",
]
