"""Plugin base classes, scheduling, rate monitoring and discovery."""

from easynav.core.plugins.controller_method_base import ControllerMethodBase
from easynav.core.plugins.declarations import (
    Param,
    ParameterValueError,
    ParameterValues,
    Topic,
    read_parameters,
)
from easynav.core.plugins.localizer_method_base import LocalizerMethodBase
from easynav.core.plugins.maps_manager_base import MapsManagerBase
from easynav.core.plugins.method_base import MethodBase, PluginConfigurationError
from easynav.core.plugins.planner_method_base import PlannerMethodBase
from easynav.core.plugins.plugin_context import (
    DictParameters,
    ParameterAccess,
    PluginContext,
    PluginServices,
    ServiceUnavailableError,
)
from easynav.core.plugins.rate_monitor import RateMonitor
from easynav.core.plugins.rate_schedule import RateSchedule
from easynav.core.plugins.recovery_manager_base import RecoveryActions, RecoveryManagerBase

__all__ = [
    "ControllerMethodBase",
    "DictParameters",
    "LocalizerMethodBase",
    "MapsManagerBase",
    "MethodBase",
    "Param",
    "ParameterValueError",
    "ParameterValues",
    "ParameterAccess",
    "PlannerMethodBase",
    "PluginConfigurationError",
    "PluginContext",
    "PluginServices",
    "RateMonitor",
    "RateSchedule",
    "RecoveryActions",
    "RecoveryManagerBase",
    "ServiceUnavailableError",
    "Topic",
    "read_parameters",
]
