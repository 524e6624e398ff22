"""Errors of the sensors package."""

from __future__ import annotations

from easynav.core.plugins.method_base import PluginConfigurationError


class SensorsConfigurationError(PluginConfigurationError):
    """sensors_node cannot be configured; the message names the parameter."""


class PerceptionConversionError(ValueError):
    """A sensor message cannot be turned into a perception; the message says what is wrong."""
