"""RecoveryManagerBase: the one plugin that is the whole recovery system."""

from __future__ import annotations

from typing import Any

from easynav.core.nav_state import NavState
from easynav.core.plugins.method_base import MethodBase
from easynav.core.types import Twist


class RecoveryActions:
    """The system actions a recovery manager may take; implemented by the recovery node.

    Thread contract: ``command_velocity`` and ``override_velocity`` are for the RT thread
    (``update_rt``); the others for either loop. None of them blocks.
    """

    def command_velocity(self, twist: Twist) -> None:
        """TAKEOVER: drive the robot this RT cycle (smoothed)."""
        raise NotImplementedError

    def override_velocity(self, twist: Twist) -> None:
        """OVERRIDE: emergency command this RT cycle, published as is."""
        raise NotImplementedError

    def abort_mission(self, reason: str) -> None:
        """End the mission with ERROR and ``reason`` on the goal client."""
        raise NotImplementedError

    def hold_mission_progress(self, hold: bool) -> None:
        """While held, reached waypoints are not removed."""
        raise NotImplementedError

    def request_shutdown(self, reason: str) -> None:
        """Controlled stop, exit code 1 (the first reason is kept)."""
        raise NotImplementedError

    def request_reconfigure(self, changes: list[tuple[str, str, Any]], reason: str) -> bool:
        """Change ``(node, parameter, value)`` between non-RT cycles through a reconfiguration."""
        raise NotImplementedError

    def request_restore_parameters(self, reason: str) -> bool:
        """Undo every reconfiguration made by the recovery system."""
        raise NotImplementedError


class RecoveryManagerBase(MethodBase):
    """A recovery system: ``update`` runs every non-RT cycle after everything else; ``update_rt``
    every RT cycle after the controller proposed and before publication, and returns whether it
    commanded the robot. An exception in ``update_rt`` gives a zero OVERRIDE.
    """

    HAS_RT_UPDATE = True
    HAS_UPDATE = True

    @property
    def actions(self) -> RecoveryActions:
        """The system actions (see :class:`RecoveryActions`); :class:`ServiceUnavailableError`
        when the host offers none."""
        return self.context.services.require_recovery_actions()

    def update(self, nav_state: NavState) -> None:
        """Diagnose and decide. Non-RT thread."""

    def update_rt(self, nav_state: NavState) -> bool:
        """Fast reactions. RT thread. True when it commanded the robot this cycle."""
        return False

    def on_unload(self) -> None:
        """Called before the manager is released; mission progress holds are released too."""
