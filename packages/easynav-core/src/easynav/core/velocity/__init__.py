"""Velocity output of controller_node: mux, smoother, command guard and their facade.

Pure logic, no ROS: controller_node calls :meth:`VelocityOutput.cycle` once per RT cycle and
publishes what it returns. See ``README.md`` beside this file.
"""

from easynav.core.velocity.command_guard import CommandGuard
from easynav.core.velocity.mux_selection import MuxSelection
from easynav.core.velocity.velocity_command import VelocityCommand
from easynav.core.velocity.velocity_mux import VelocityMux
from easynav.core.velocity.velocity_output import VelocityOutput
from easynav.core.velocity.velocity_smoother import VelocitySmoother
from easynav.core.velocity.velocity_source import VelocitySource

__all__ = [
    "CommandGuard",
    "MuxSelection",
    "VelocityCommand",
    "VelocityMux",
    "VelocityOutput",
    "VelocitySmoother",
    "VelocitySource",
]
