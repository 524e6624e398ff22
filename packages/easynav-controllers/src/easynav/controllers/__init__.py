"""EasyNav controllers: SimpleController (carrot following with PIDs).

The algorithm (:class:`SimplePathFollower`, :class:`PIDController`) is plain Python/numpy; the
plugin (``easynav.controllers.simple_controller``) is not imported here.
"""

from easynav.controllers.path_follower import (
    ARRIVED,
    FINAL_ROTATION,
    FOLLOWING,
    NO_PATH,
    SimplePathFollower,
    carrot_on_path,
)
from easynav.controllers.pid_controller import PIDController

__all__ = [
    "ARRIVED",
    "FINAL_ROTATION",
    "FOLLOWING",
    "NO_PATH",
    "PIDController",
    "SimplePathFollower",
    "carrot_on_path",
]
