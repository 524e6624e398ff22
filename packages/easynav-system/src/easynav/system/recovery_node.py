"""RecoveryNode: hosts the recovery system and implements its system actions."""

from __future__ import annotations

from easynav.core.nav_state_keys import PROPOSAL_OVERRIDE, PROPOSAL_TAKEOVER
from easynav.core.plugins import RecoveryActions
from easynav.core.plugins.plugin_kinds import RECOVERY_MANAGER
from easynav.core.types import Twist
from easynav.system.component_node import ComponentNode
from easynav.system.system_requests import ParameterChange, ReconfigureRequest, SystemRequests

DEFAULT_RECOVERY_MANAGER = "easynav_recovery/DummyRecoveryManager"


class NodeRecoveryActions(RecoveryActions):
    """The system actions, as recovery_node offers them to its manager.

    Velocity proposals go to NavState (``cmd_vel.proposal.takeover|override``) for this RT
    cycle; everything else is posted to system_node, which applies it between non-RT cycles.
    """

    def __init__(self, node: RecoveryNode) -> None:
        self._node = node

    @property
    def _requests(self) -> SystemRequests:
        return self._node.system.services.requests

    def command_velocity(self, twist: Twist) -> None:
        self._node.nav_state.set(PROPOSAL_TAKEOVER, twist)

    def override_velocity(self, twist: Twist) -> None:
        self._node.nav_state.set(PROPOSAL_OVERRIDE, twist)

    def abort_mission(self, reason: str) -> None:
        self._requests.post_abort(reason)

    def hold_mission_progress(self, hold: bool) -> None:
        self._requests.hold_progress = bool(hold)

    def request_shutdown(self, reason: str) -> None:
        self._node.get_logger().error(f"recovery system requests a shutdown: {reason}")
        self._requests.post_shutdown(reason, 1)

    def request_reconfigure(self, changes: list[ParameterChange], reason: str) -> bool:
        check = self._node.system.services.check_reconfigure
        if check is None:
            return False
        ok, why = check(changes)
        if not ok:
            self._node.get_logger().warning(f"reconfiguration refused ({reason}): {why}")
            return False
        self._requests.post_reconfigure(ReconfigureRequest(list(changes), reason))
        return True

    def request_restore_parameters(self, reason: str) -> bool:
        check = self._node.system.services.check_reconfigure
        if check is None:
            return False
        ok, why = check([])
        if not ok:
            self._node.get_logger().warning(f"parameter restore refused ({reason}): {why}")
            return False
        self._requests.post_reconfigure(ReconfigureRequest([], reason, restore=True))
        return True


class RecoveryNode(ComponentNode):
    """recovery_node: ``recovery_manager.plugin`` (default the Dummy one) and its parameters.

    ``update_rt`` runs every RT cycle after the controller, ``update`` every non-RT cycle after
    everything else. An exception in ``update_rt`` gives a zero OVERRIDE.

    Thread contract: ``cycle_rt`` in the RT thread, ``cycle`` in the non-RT thread.
    """

    KIND = RECOVERY_MANAGER
    DEFAULT_ALIAS_PLUGIN = ("recovery_manager", DEFAULT_RECOVERY_MANAGER)
    MONITOR_RT = False
    MONITOR_NON_RT = False

    def __init__(self, namespace, system, **kwargs):
        super().__init__("recovery_node", namespace, system, **kwargs)
        self.actions = NodeRecoveryActions(self)
        system.services.recovery_actions = self.actions

    def release_plugins(self) -> None:
        for lp in self.plugins:
            try:
                lp.plugin.on_unload()
            except Exception as exc:
                self.get_logger().warning(f"{lp.alias}: on_unload failed: {exc}")
        if self.plugins:
            # Holds are released when the manager is unloaded.
            self.system.services.requests.hold_progress = False
        super().release_plugins()

    def cycle_rt(self) -> bool:
        """The manager's fast reactions; True when it commanded the robot. RT thread."""
        if not self.active or self.now_seconds() <= 0.0:  # simulated time not started yet
            return False
        commanded = False
        for lp in self.plugins:
            ok, result = self.run_plugin(lp, "update_rt")
            if not ok:
                self.actions.override_velocity(Twist())  # contained: brake now
                commanded = True
            else:
                commanded = commanded or bool(result)
        return commanded

    def cycle(self) -> None:
        """The manager's diagnosis and decisions. Non-RT thread."""
        if not self.active or self.now_seconds() <= 0.0:  # simulated time not started yet
            return
        for lp in self.plugins:
            self.run_plugin(lp, "update")
