"""FaultyController (easynav_controller/FaultyController): a constant velocity that goes wrong."""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL
from easynav.core.plugins import ControllerMethodBase, Param
from easynav.core.types import Header, Twist, TwistStamped
from easynav.faulty.fault_injector import FaultInjector

#: Velocity of the ``max_velocity`` fault (m/s and rad/s): far beyond any robot's limits.
ABSURD_VELOCITY = 1000.0


class FaultyController(ControllerMethodBase):
    """Works as a constant-velocity controller, then injects a fault (fault-injection tests).

    Normal update: writes NavState ``cmd_vel`` = :class:`TwistStamped` (``vx`` = ``linear_vel``,
    ``wz`` = ``angular_vel``, frame the robot footprint frame) stamped with the node clock, a
    new command every update.

    Faults (``<alias>.fault``, from update ``fault_after`` + 1 on, see :class:`FaultInjector`):

    ========================= ====================================================================
    ``throw``                 ``update_rt`` raises :class:`InjectedFaultError`
    ``hang``                  ``update_rt`` blocks ``hang_time`` s, then works normally
    ``stop_proposing``        writes nothing: ``cmd_vel`` keeps the last command, no new one
    ``freeze``                writes the last normal command again, same stamp and value
    ``max_velocity``          writes ``vx``, ``wz`` = ±1000 (signs of ``linear_vel``,
                              ``angular_vel``), stamped now
    ``nan``                   writes NaN ``vx`` and ``wz``, stamped now
    ========================= ====================================================================

    Parameters: :attr:`PARAMETERS`.

    Thread contract: ``initialize`` in the configuring thread; ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter; ``update_rt`` raises
    :class:`InjectedFaultError` with the ``throw`` fault (on purpose: the host contains it).
    """

    FAULTS = ("throw", "hang", "stop_proposing", "freeze", "max_velocity", "nan")
    PARAMETERS = (
        Param("linear_vel", 0.1, "forward velocity commanded", "m/s"),
        Param("angular_vel", 0.0, "turning velocity commanded", "rad/s"),
        *FaultInjector.parameters(FAULTS),
    )
    WRITES = (CMD_VEL,)

    def __init__(self) -> None:
        super().__init__()
        self.injector = FaultInjector(self, self.FAULTS)
        self.linear_vel = 0.1
        self.angular_vel = 0.0
        self.last_command: TwistStamped | None = None

    def on_initialize(self) -> None:
        self.linear_vel = self.params.linear_vel
        self.angular_vel = self.params.angular_vel
        self.injector.read_parameters()
        self.last_command = None

    def on_parameter_changed(self, name: str, value: object) -> None:
        """The velocities apply from the next update."""
        self.linear_vel = self.params.linear_vel
        self.angular_vel = self.params.angular_vel

    def update_rt(self, nav_state: NavState) -> None:
        fault = self.injector.update()
        if fault == "throw":
            self.injector.throw("update_rt")
        if fault == "hang":
            self.injector.hang()
        if fault == "stop_proposing":
            return
        if fault == "freeze":
            # Frozen at the last normal command (or at the first one, with fault_after 0).
            if self.last_command is None:
                self.last_command = self._stamped(Twist(vx=self.linear_vel, wz=self.angular_vel))
            nav_state.set(CMD_VEL, self.last_command)
            return
        if fault == "max_velocity":
            twist = Twist(
                vx=math.copysign(ABSURD_VELOCITY, self.linear_vel),
                wz=math.copysign(ABSURD_VELOCITY, self.angular_vel),
            )
        elif fault == "nan":
            twist = Twist(vx=math.nan, wz=math.nan)
        else:
            twist = Twist(vx=self.linear_vel, wz=self.angular_vel)
        command = self._stamped(twist)
        if fault is None or fault == "hang":
            self.last_command = command
        nav_state.set(CMD_VEL, command)

    def _stamped(self, twist: Twist) -> TwistStamped:
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        return TwistStamped(Header(self.now(), frame), twist)
