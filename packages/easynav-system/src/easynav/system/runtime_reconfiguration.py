"""RuntimeReconfiguration: parameter changes requested by the recovery system, applied through
the lifecycle (active → inactive → unconfigured → inactive → active) between non-RT cycles.
"""

from __future__ import annotations

from typing import Any

from rclpy.parameter import Parameter

from easynav.core.nav_state_keys import RECONFIGURED_PARAMETERS
from easynav.system.component_node import ComponentNode
from easynav.system.ros.rclpy_private import parameter_override, set_parameter_override
from easynav.system.system_extension import SystemExtension
from easynav.system.system_requests import ReconfigureRequest


class RuntimeReconfiguration(SystemExtension):
    """Applies :class:`ReconfigureRequest` s posted by ``request_reconfigure`` /
    ``request_restore_parameters``.

    - ``check(changes)``: refused when reconfiguration is not allowed (safety mode), when a
      node or parameter is unknown (neither declared on that node nor given in its params file),
      or when the value breaks the parameter's declaration (the reason names the rule).
    - Between non-RT cycles: deactivate (the robot brakes and stays stopped), clean up, set the
      parameters, configure, activate. The mission survives (the goal manager is kept). If the
      new configuration fails, the old values are restored and configured again.
    - Every changed parameter is listed as ``node/param`` in NavState
      ``reconfigured_parameters`` (list of str); a restore sets every one back to the value it
      had before the first change and empties the list.

    Thread contract: ``check`` from any thread (reads parameters); ``between_cycles`` in the
    non-RT thread (system_node calls it after each non-RT cycle).
    """

    def __init__(self, system_node) -> None:
        self.node = system_node
        self.originals: dict[tuple[str, str], Any] = {}
        self.allowed = lambda: (True, "")  # replaced by the safety supervisor (frozen config)
        system_node.system.services.check_reconfigure = self.check

    def _target(self, node_name: str):
        if node_name == "system_node":
            return self.node
        return self.node.subnodes.get(node_name)

    def check(self, changes: list[tuple[str, str, Any]]) -> tuple[bool, str]:
        ok, why = self.allowed()
        if not ok:
            return False, why
        for node_name, name, value in changes:
            target = self._target(node_name)
            if target is None:
                return False, f"unknown node '{node_name}'"
            if not (target.has_parameter(name) or parameter_override(target, name) is not None):
                return False, f"unknown parameter '{node_name}/{name}'"
            # The same rules as any change (the node's or the loaded plugin's declaration).
            if isinstance(target, ComponentNode):
                try:
                    target.check_parameter_change(name, value, reconfiguring=True)
                except ValueError as exc:
                    return False, str(exc)
        return True, ""

    def between_cycles(self) -> None:
        for request in self.node.requests.take_reconfigure():
            self.apply(request)

    def apply(self, request: ReconfigureRequest) -> bool:
        """Run one reconfiguration; True when the new values are in force."""
        logger = self.node.get_logger()
        if request.restore:
            changes = [(n, p, v) for (n, p), v in self.originals.items()]
        else:
            ok, why = self.check(request.changes)
            if not ok:
                logger.warning(f"reconfiguration refused ({request.reason}): {why}")
                return False
            changes = list(request.changes)
        if not changes:
            return True
        previous = {(n, p): self._current(n, p) for n, p, _ in changes}
        logger.warning(
            f"reconfiguring ({request.reason}): "
            + ", ".join(f"{n}/{p} = {v!r}" for n, p, v in changes)
        )
        if self._reconfigure(changes):
            if request.restore:
                self.originals.clear()
            else:
                for key, value in previous.items():
                    self.originals.setdefault(key, value)
            self._publish_list()
            return True
        logger.error(f"reconfiguration failed ({self.node.error_message}): restoring")
        self._reconfigure([(n, p, v) for (n, p), v in previous.items() if v is not None])
        return False

    def _current(self, node_name: str, name: str) -> Any:
        target = self._target(node_name)
        if target.has_parameter(name):
            return target.get_parameter(name).value
        override = parameter_override(target, name)
        return None if override is None else override.value

    def _reconfigure(self, changes: list[tuple[str, str, Any]]) -> bool:
        node = self.node
        if node.lifecycle_state() == "active":
            node.trigger_deactivate()
        if node.lifecycle_state() == "inactive":
            node.trigger_cleanup()
        try:
            for node_name, name, value in changes:
                self._set(self._target(node_name), name, value)
        except Exception as exc:
            node.error_message = str(exc)
            node.trigger_configure()
            if node.lifecycle_state() == "inactive":
                node.trigger_activate()
            return False
        node.trigger_configure()
        if node.lifecycle_state() != "inactive":
            return False
        node.trigger_activate()
        return node.lifecycle_state() == "active"

    @staticmethod
    def _set(target, name: str, value: Any) -> None:
        if target.has_parameter(name):
            current = target.get_parameter(name).value
            if isinstance(current, float) and type(value) is int:
                value = float(value)
            result = target.set_parameters([Parameter(name, value=value)])[0]
            if not result.successful:
                raise ValueError(f"{target.get_name()}/{name}: {result.reason}")
        else:
            set_parameter_override(target, name, value)

    def _publish_list(self) -> None:
        names = sorted(f"{n}/{p}" for n, p in self.originals)
        self.node.nav_state.set(RECONFIGURED_PARAMETERS, names)
