"""Reading the Faulty plugins' numeric parameters with errors that name them."""

from __future__ import annotations

import math

from easynav.core.plugins import MethodBase, PluginConfigurationError


def finite_parameter(plugin: MethodBase, name: str, default: float, description: str = "") -> float:
    """Declare-if-absent ``<alias>.<name>`` and return it as a finite float.

    Raises :class:`PluginConfigurationError` naming ``<alias>.<name>`` when the value is not a
    number (a bool included) or not finite. Configuring thread.
    """
    value = plugin.get_parameter(name, default, description)
    full = f"{plugin.plugin_name}.{name}"
    if isinstance(value, bool):
        raise PluginConfigurationError(f"{full} = {value!r} is not a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise PluginConfigurationError(f"{full} = {value!r} is not a number") from None
    if not math.isfinite(number):
        raise PluginConfigurationError(f"{full} = {number} must be finite")
    return number
