"""Checked parameter reads for recovery plugins: a bad value fails configure naming it.

Every function declares-if-absent ``<plugin_name>.<name>`` on the host node (through
``MethodBase.get_parameter``) and raises :class:`PluginConfigurationError` naming the parameter,
its value and what was expected. Thread contract: the configuring thread (``on_initialize``).
"""

from __future__ import annotations

import math
from typing import Any

from easynav.core.plugins import MethodBase, PluginConfigurationError


def _full(plugin: MethodBase, name: str) -> str:
    return f"{plugin.plugin_name}.{name}"


def read_float(
    plugin: MethodBase,
    name: str,
    default: float,
    *,
    minimum: float | None = 0.0,
    positive: bool = False,
    allow_nan: bool = False,
    description: str = "",
) -> float:
    """A finite float (``>= minimum``, or ``> 0`` with ``positive``); NaN only if allowed."""
    raw = plugin.get_parameter(name, default, description)
    if isinstance(raw, bool):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {raw!r} is not a number")
    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {raw!r} is not a number") from None
    if math.isnan(value):
        if allow_nan:
            return value
        raise PluginConfigurationError(f"{_full(plugin, name)} = nan must be a finite number")
    if not math.isfinite(value):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {value} must be finite")
    if positive and value <= 0.0:
        raise PluginConfigurationError(f"{_full(plugin, name)} = {value:g} must be > 0")
    if minimum is not None and value < minimum:
        raise PluginConfigurationError(f"{_full(plugin, name)} = {value:g} must be >= {minimum:g}")
    return value


def read_int(plugin: MethodBase, name: str, default: int, *, minimum: int | None = 0) -> int:
    """An integer (an integral float such as ``3.0`` is accepted), ``>= minimum``."""
    raw = plugin.get_parameter(name, default)
    if isinstance(raw, bool) or not isinstance(raw, int | float):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {raw!r} is not an integer")
    if isinstance(raw, float) and not (math.isfinite(raw) and raw.is_integer()):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {raw!r} is not an integer")
    value = int(raw)
    if minimum is not None and value < minimum:
        raise PluginConfigurationError(f"{_full(plugin, name)} = {value} must be >= {minimum}")
    return value


def read_bool(plugin: MethodBase, name: str, default: bool) -> bool:
    """A boolean (true/false in YAML)."""
    raw = plugin.get_parameter(name, default)
    if not isinstance(raw, bool):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {raw!r} is not true or false")
    return raw


def read_str_list(plugin: MethodBase, name: str, default: list[str]) -> list[str]:
    """A list of non-empty strings."""
    raw: Any = plugin.get_parameter(name, list(default))
    if isinstance(raw, str) or not isinstance(raw, list | tuple):
        raise PluginConfigurationError(f"{_full(plugin, name)} = {raw!r} is not a list of names")
    values = list(raw)
    for item in values:
        if not isinstance(item, str) or not item:
            raise PluginConfigurationError(
                f"{_full(plugin, name)} = {values!r}: every item must be a non-empty string"
            )
    return values
