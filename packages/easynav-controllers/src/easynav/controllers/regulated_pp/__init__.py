"""Regulated Pure Pursuit (easynav_regulated_pp_controller): algorithm and plugin.

The algorithm (:class:`RegulatedPurePursuit`) and its regulation laws are plain Python/numpy;
the plugin module (``regulated_pp_controller``) is not imported here.
"""

from easynav.controllers.regulated_pp.regulated_pure_pursuit import (
    ARRIVED,
    FOLLOWING,
    NO_PATH,
    ROTATING_TO_GOAL,
    ROTATING_TO_HEADING,
    RPP_PARAMETERS,
    RegulatedPurePursuit,
    RppCommand,
)

__all__ = [
    "ARRIVED",
    "FOLLOWING",
    "NO_PATH",
    "ROTATING_TO_GOAL",
    "ROTATING_TO_HEADING",
    "RPP_PARAMETERS",
    "RegulatedPurePursuit",
    "RppCommand",
]
