"""NodeParameters: declare-if-absent-and-read parameters on an rclpy node."""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.exceptions import (
    InvalidParameterTypeException,
    ParameterException,
    ParameterUninitializedException,
)
from rclpy.parameter import Parameter

from easynav.core.plugins.plugin_context import ParameterAccess
from easynav.system.ros.rclpy_private import parameter_override


class ParameterError(ValueError):
    """A parameter has a value of the wrong type or cannot be declared; names the parameter."""


class NodeParameters(ParameterAccess):
    """:class:`ParameterAccess` backed by an rclpy node.

    Values come from the params file (parameter overrides) or the default. An integer written
    where a double is expected (``rt_freq: 30``) is accepted as a double, as users of the C++
    original expect YAML numbers to be numbers; any other type mismatch is a
    :class:`ParameterError` naming ``<node>.<parameter>``.

    :meth:`is_set` is true for a parameter given in the params file (or ``-p``) and for one set
    later (``ros2 param set``, a recovery mitigation's reconfiguration): rclpy calls
    pre-set callbacks for ``set_parameters`` only, not for declarations, which is how a change is
    told from a declaration.

    Thread contract: configuring thread (lifecycle transitions), or any thread for reads of
    declared parameters; the callbacks run in the thread that sets parameters.
    """

    def __init__(self, node: Any) -> None:
        self._node = node
        self._pending: set[str] = set()
        self.changed: set[str] = set()  # names set after their declaration, not defaults
        #: Called with ``(name, value)`` after each successful change (not declarations).
        self.listeners: list[Any] = []
        node.add_pre_set_parameters_callback(self._before_set)
        node.add_post_set_parameters_callback(self._after_set)

    def _before_set(self, parameters: list[Parameter]) -> list[Parameter]:
        self._pending.update(p.name for p in parameters)
        return parameters

    def _after_set(self, parameters: list[Parameter]) -> None:
        for parameter in parameters:
            if parameter.name in self._pending:
                self._pending.discard(parameter.name)
                self.changed.add(parameter.name)
                for listener in self.listeners:
                    listener(parameter.name, parameter.value)

    def is_changing(self, name: str) -> bool:
        """Whether ``name`` is being set right now (``set_parameters``), not declared."""
        return name in self._pending

    def forget_pending(self, name: str) -> None:
        """A set of ``name`` was refused: it is not pending any more."""
        self._pending.discard(name)

    def declare(self, name: str, default: Any, description: str = "") -> Any:
        node = self._node
        if node.has_parameter(name):
            try:
                return node.get_parameter(name).value
            except ParameterUninitializedException:  # an empty list declared by type only
                return [] if isinstance(default, list) else default
        descriptor = ParameterDescriptor(description=description)
        override = parameter_override(node, name)
        try:
            if (
                isinstance(default, list)
                and override is not None
                and override.type_ == Parameter.Type.NOT_SET
            ):
                # ``filters: []`` in a params file: rclpy reads an empty YAML list as NOT_SET.
                # The user meant an empty list: declare it typed like the default, empty.
                kind = (
                    Parameter.Type.from_parameter_value(default)
                    if default
                    else Parameter.Type.STRING_ARRAY
                )
                node.declare_parameter(name, kind, descriptor, ignore_override=True)
                return []
            if isinstance(default, list) and not default:
                # An empty list has no type of its own: the override's type wins, strings else.
                if override is not None:
                    node.declare_parameter(name, override.value, descriptor, ignore_override=True)
                else:
                    node.declare_parameter(name, Parameter.Type.STRING_ARRAY, descriptor)
                    return []
            elif (
                override is not None
                and isinstance(default, float)
                and type(override.value) is int
            ):
                node.declare_parameter(name, float(override.value), descriptor, True)
            else:
                node.declare_parameter(name, default, descriptor)
        except InvalidParameterTypeException as exc:
            got = override.value if override is not None else None
            raise ParameterError(
                f"{node.get_name()}.{name} = {got!r} has the wrong type: expected "
                f"{type(default).__name__} like the default {default!r}"
            ) from exc
        except ParameterException as exc:
            raise ParameterError(f"{node.get_name()}.{name}: {exc}") from exc
        return node.get_parameter(name).value

    def set(self, name: str, value: Any) -> None:
        result = self._node.set_parameters([Parameter(name, value=value)])[0]
        if not result.successful:
            raise ParameterError(f"{self._node.get_name()}.{name}: {result.reason}")

    def is_set(self, name: str) -> bool:
        return parameter_override(self._node, name) is not None or name in self.changed

    def get(self, name: str) -> Any:
        """The value of a declared parameter."""
        return self._node.get_parameter(name).value
