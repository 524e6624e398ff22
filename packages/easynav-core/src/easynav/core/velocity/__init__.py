"""Velocity output of controller_node: one velocity decision per RT cycle.

Pure logic, no ROS: :func:`decide_velocity` applies every rule (mux, protective stop, limits in
force, NaN/inf refusal, cmd_timeout, acceleration ramp, publication) once to a frozen
:class:`CycleInput` and :class:`VelocityState`; controller_node calls it through
:meth:`VelocityOutput.cycle` once per RT cycle and publishes what it returns. The mux, smoother
and guard classes are stateful views of single rules. See ``README.md`` beside this file.
"""

from easynav.core.velocity.command_guard import CommandGuard
from easynav.core.velocity.cycle_input import CycleInput
from easynav.core.velocity.mux_selection import MuxSelection
from easynav.core.velocity.velocity_command import VelocityCommand
from easynav.core.velocity.velocity_decision import VelocityDecision, decide_velocity
from easynav.core.velocity.velocity_mux import VelocityMux
from easynav.core.velocity.velocity_output import VelocityOutput
from easynav.core.velocity.velocity_rules import limits_in_force
from easynav.core.velocity.velocity_smoother import VelocitySmoother
from easynav.core.velocity.velocity_source import VelocitySource
from easynav.core.velocity.velocity_state import VelocityState

__all__ = [
    "CommandGuard",
    "CycleInput",
    "MuxSelection",
    "VelocityCommand",
    "VelocityDecision",
    "VelocityMux",
    "VelocityOutput",
    "VelocitySmoother",
    "VelocitySource",
    "VelocityState",
    "decide_velocity",
    "limits_in_force",
]
