"""What a plugin declares about itself, once, as data: parameters, topics, NavState keys.

A plugin class lists its parameters in ``PARAMETERS`` (a tuple of :class:`Param`), the topics it
uses in ``TOPICS`` (:class:`Topic`) and the NavState keys it reads and writes in ``READS`` and
``WRITES`` (:class:`~easynav.core.nav_state_keys.NavStateKey`). Everything else comes from these
declarations: declaration on the host node, conversion and validation at configure time and at
every runtime change (``ros2 param set``, a recovery mitigation), deprecated names, the README
tables, ``easynav plugins --describe`` and the unknown-key check of ``easynav check``.

Nothing here imports ROS: a plugin's declarations can be read and validated in a notebook.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

#: Type names a parameter can have (ROS 2 parameter types).
SCALAR_TYPES = {"float": float, "int": int, "bool": bool, "str": str}
ARRAY_TYPES = {"float[]": float, "int[]": int, "bool[]": bool, "str[]": str}


class ParameterValueError(ValueError):
    """A parameter value breaks its declaration; the message names parameter, value and rule.

    Example: ``simple.look_ahead_dist = -1.0: must be > 0``.
    """


def _type_of_default(default: Any) -> str:
    if isinstance(default, bool):
        return "bool"
    if isinstance(default, int):
        return "int"
    if isinstance(default, float):
        return "float"
    if isinstance(default, str):
        return "str"
    if isinstance(default, (list, tuple)):
        if not default:
            raise ValueError("an empty list default needs an explicit type (type='float[]', ...)")
        return _type_of_default(default[0]) + "[]"
    raise ValueError(f"no parameter type for a default of type {type(default).__name__}")


def _bound(value: float) -> str:
    return f"{value:g}"


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    return str(value)


@dataclass(frozen=True)
class Param:
    """One parameter of a plugin (or of a node), declared once.

    ``name`` is relative to the plugin's alias (``look_ahead_dist`` is read from
    ``<alias>.look_ahead_dist``). ``type`` is one of ``float int bool str float[] int[] bool[]
    str[]``, inferred from ``default`` when omitted. Range rules: ``gt``/``ge`` (lower bound,
    exclusive/inclusive), ``lt``/``le`` (upper bound); ``choices`` the allowed values.
    ``allow_nan``: NaN is a legal value of a float parameter (meaning "unset"). ``deprecated``:
    former names of this parameter, still read with a warning; the new name wins when both are
    set. ``dynamic``: a runtime change is taken (validated by the same rules); when False a
    runtime change is refused with the reason.
    """

    name: str
    default: Any
    description: str = ""
    unit: str = ""
    type: str = ""
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    choices: tuple = ()
    allow_nan: bool = False
    deprecated: tuple[str, ...] = ()
    dynamic: bool = True

    def __post_init__(self) -> None:
        kind = self.type or _type_of_default(self.default)
        if kind not in SCALAR_TYPES and kind not in ARRAY_TYPES:
            raise ValueError(f"parameter {self.name}: unknown type {kind!r}")
        object.__setattr__(self, "type", kind)
        if isinstance(self.default, tuple):
            object.__setattr__(self, "default", list(self.default))
        if isinstance(self.deprecated, str):
            object.__setattr__(self, "deprecated", (self.deprecated,))
        # A declaration whose own default breaks its rules is a programming error: fail early.
        self.convert(self.default, self.name)

    # -- rules ---------------------------------------------------------------------------------
    def rule(self) -> str:
        """The allowed values in words: ``> 0``, ``[0, 1]``, ``one of 'a', 'b'``; "" when any."""
        if self.choices:
            return "one of " + ", ".join(_fmt(c) for c in self.choices)
        low = f"> {_bound(self.gt)}" if self.gt is not None else (
            f">= {_bound(self.ge)}" if self.ge is not None else "")
        high = f"< {_bound(self.lt)}" if self.lt is not None else (
            f"<= {_bound(self.le)}" if self.le is not None else "")
        if low and high:
            if self.ge is not None and self.le is not None:
                return f"in [{_bound(self.ge)}, {_bound(self.le)}]"
            return f"{low} and {high}"
        return low or high

    def _check_number(self, value: float, full: str, shown: Any) -> None:
        if isinstance(value, float) and math.isnan(value):
            if self.allow_nan:
                return
            raise ParameterValueError(f"{full} = {_fmt(shown)}: must be a number, not NaN")
        if isinstance(value, float) and math.isinf(value) and not self._bounded_by_inf(value):
            raise ParameterValueError(f"{full} = {_fmt(shown)}: must be finite")
        broken = (
            (self.gt is not None and not value > self.gt)
            or (self.ge is not None and not value >= self.ge)
            or (self.lt is not None and not value < self.lt)
            or (self.le is not None and not value <= self.le)
        )
        if broken:
            raise ParameterValueError(f"{full} = {_fmt(shown)}: must be {self.rule()}")

    def _bounded_by_inf(self, value: float) -> bool:
        # Infinity is legal only where the default itself is infinite ("no limit").
        default = self.default
        return isinstance(default, float) and math.isinf(default) and value == default

    def _convert_scalar(self, kind: str, value: Any, full: str) -> Any:
        if kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterValueError(f"{full} = {_fmt(value)}: must be a number (float)")
            return float(value)
        if kind == "int":
            if isinstance(value, float) and value.is_integer():
                return int(value)
            if isinstance(value, bool) or not isinstance(value, int):
                raise ParameterValueError(f"{full} = {_fmt(value)}: must be an integer")
            return value
        if kind == "bool":
            if not isinstance(value, bool):
                raise ParameterValueError(f"{full} = {_fmt(value)}: must be true or false")
            return value
        if not isinstance(value, str):
            raise ParameterValueError(f"{full} = {_fmt(value)}: must be a string")
        return value

    def convert(self, value: Any, full_name: str | None = None) -> Any:
        """``value`` converted to this parameter's type and checked against its rules.

        An integer is accepted for a float (YAML ``rt_freq: 30``). Raises
        :class:`ParameterValueError` naming ``full_name``, the value and the rule.
        """
        full = full_name or self.name
        if self.type in ARRAY_TYPES:
            if not isinstance(value, (list, tuple)):
                raise ParameterValueError(f"{full} = {_fmt(value)}: must be a list ({self.type})")
            kind = self.type[:-2]
            items = [self._convert_scalar(kind, v, full) for v in value]
            if kind in ("float", "int"):
                for item in items:
                    self._check_number(item, full, value)
            if self.choices:
                for item in items:
                    if item not in self.choices:
                        raise ParameterValueError(f"{full} = {_fmt(value)}: must be {self.rule()}")
            return items
        converted = self._convert_scalar(self.type, value, full)
        if self.choices:
            if converted not in self.choices:
                raise ParameterValueError(f"{full} = {_fmt(value)}: must be {self.rule()}")
        elif self.type in ("float", "int"):
            self._check_number(converted, full, value)
        return converted

    def describe_default(self) -> str:
        """The default as a README / ``--describe`` cell."""
        if isinstance(self.default, float) and math.isnan(self.default):
            return "unset"
        return _fmt(self.default)


@dataclass(frozen=True)
class Topic:
    """A topic a plugin publishes or subscribes to (relative to its host node unless absolute).

    ``direction``: ``pub`` or ``sub``. ``qos``: a short description (``latched``, ``sensor``...).
    """

    name: str
    message_type: str
    direction: str
    qos: str = "reliable"
    description: str = ""

    def __post_init__(self) -> None:
        if self.direction not in ("pub", "sub"):
            raise ValueError(f"topic {self.name}: direction must be 'pub' or 'sub'")


class ParameterValues(Mapping):
    """A plugin's parameter values after validation: ``params.look_ahead_dist``, ``params["k"]``.

    Runtime changes go through :meth:`set` after the host has validated them; plugins read
    ``self.params.<name>`` when they need a value (every cycle), so a change takes effect at once.
    """

    def __init__(self, values: Mapping[str, Any] | None = None) -> None:
        object.__setattr__(self, "_values", dict(values or {}))

    def __getattr__(self, name: str) -> Any:
        try:
            return self._values[name]
        except KeyError:
            raise AttributeError(f"no parameter {name!r} was declared") from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("parameter values change through set() after validation")

    def __getitem__(self, name: str) -> Any:
        return self._values[name]

    def __iter__(self):
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def set(self, name: str, value: Any) -> None:
        """Store an already validated value."""
        self._values[name] = value

    def __repr__(self) -> str:
        return f"ParameterValues({self._values!r})"


def merge_declarations(groups: Iterable[Iterable[Param]]) -> tuple[Param, ...]:
    """Declarations of several groups in order; a later one replaces an earlier one of its name."""
    merged: dict[str, Param] = {}
    for group in groups:
        for param in group:
            merged.pop(param.name, None)
            merged[param.name] = param
    return tuple(merged.values())


def read_parameters(
    declarations: Iterable[Param],
    access: Any,
    prefix: str,
    warn: Any = None,
) -> ParameterValues:
    """Declare every parameter on ``access`` (a ParameterAccess) under ``prefix`` and read it.

    ``prefix`` is the plugin alias (``simple``) or "" for node-level parameters. A deprecated name
    that the user set is read when the new name is not set, with one warning through ``warn``
    (a callable taking a message); when both are set the new name wins, with a warning that the
    old one is ignored. Raises :class:`ParameterValueError` naming the first broken parameter.
    """
    values: dict[str, Any] = {}
    for param in declarations:
        full = f"{prefix}.{param.name}" if prefix else param.name
        raw = access.declare(full, param.default, param.description)
        value = param.convert(raw, full)
        for old in param.deprecated:
            old_full = f"{prefix}.{old}" if prefix else old
            if not access.is_set(old_full):
                continue
            old_raw = access.declare(old_full, param.default, f"deprecated: use {full}")
            if access.is_set(full):
                if warn is not None:
                    warn(f"{old_full} is deprecated and ignored: {full} is set")
                continue
            value = param.convert(old_raw, old_full)
            if warn is not None:
                warn(f"{old_full} is deprecated: use {full} (applied: {_fmt(value)})")
        values[param.name] = value
    return ParameterValues(values)


def declared_names(declarations: Iterable[Param]) -> set[str]:
    """Every name a params file may use for these declarations (current and deprecated)."""
    names: set[str] = set()
    for param in declarations:
        names.add(param.name)
        names.update(param.deprecated)
    return names
