"""MPPI (easynav_mppi_controller): optimiser, batch, critics; the plugin is not imported here."""

from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.critics import CRITICS, DEFAULT_CRITICS
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.controllers.mppi.mppi_optimizer import (
    MPPI_PARAMETERS,
    MppiCommand,
    MppiOptimizer,
)

__all__ = [
    "CRITICS",
    "DEFAULT_CRITICS",
    "MPPI_PARAMETERS",
    "Critic",
    "MppiBatch",
    "MppiCommand",
    "MppiOptimizer",
]
