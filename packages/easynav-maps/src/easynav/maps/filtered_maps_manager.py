"""FilteredMapsManager: a maps manager that runs ordered filter plugins over its map."""

from __future__ import annotations

from typing import Any

from easynav.core.plugins import MapsManagerBase, PluginConfigurationError
from easynav.core.plugins.declarations import ParameterValueError
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.plugin_kinds import PluginKind


class FilteredMapsManager(MapsManagerBase):
    """The filter chain shared by the costmap, NavMap and routes maps managers.

    ``<alias>.filters`` lists filter aliases in the order they run; ``<alias>.<filter>.plugin``
    names each one's plugin (a class of the entry-point group of :attr:`FILTER_KIND`) and its
    own parameters live under ``<alias>.<filter>.*``. Runtime changes of those parameters are
    routed to the filter; ``filters``, any ``*.plugin`` and the names in :attr:`RUNTIME_FIXED`
    cannot change at runtime (a reconfiguration reloads the manager).

    Subclasses set :attr:`FILTER_KIND`, :attr:`FILTER_EXAMPLE` (a plugin string for the error
    of an alias without one) and call :meth:`_load_filters` from ``on_initialize`` and
    :meth:`_cleanup_filters` where they release their resources.

    Thread contract: loading and cleanup in the configuring thread; the parameter routing in
    the thread that applies runtime changes (the owner's). Exceptions: loading raises
    :class:`PluginConfigurationError` naming the parameter (the filters loaded before it are
    cleaned up); cleanup logs a filter's failure and goes on with the others.
    """

    #: The filters' plugin kind (entry-point group and base class).
    FILTER_KIND: PluginKind
    #: A filter plugin string, quoted when an alias has no ``plugin``.
    FILTER_EXAMPLE = ""
    #: Parameters besides ``filters`` and ``*.plugin`` that cannot change at runtime.
    RUNTIME_FIXED: tuple[str, ...] = ()

    def __init__(self) -> None:
        super().__init__()
        self._filters: list[tuple[str, Any]] = []

    def sub_plugins(self) -> list:
        """The loaded filters (runtime parameter changes of ``<alias>.<filter>.*`` go to them)."""
        return [instance for _, instance in self._filters]

    @property
    def filters(self) -> list[tuple[str, Any]]:
        """The loaded filters ``(alias, filter)`` in order."""
        return list(self._filters)

    def _load_filters(self, aliases: list[str]) -> list[tuple[str, Any]]:
        """Load and initialise the filters of ``aliases``, in order."""
        node = self.context.node_name or "maps_manager_node"
        kind = self.FILTER_KIND.name
        if len(set(aliases)) != len(aliases):
            raise PluginConfigurationError(
                f"{self.plugin_name}.filters = {aliases}: an alias is listed twice (each names "
                f"its own parameters, {self.plugin_name}.<filter>.*)"
            )
        loaded: list[tuple[str, Any]] = []
        try:
            for alias in aliases:
                parameter = f"{node}.{self.plugin_name}.{alias}.plugin"
                name = self.get_parameter(f"{alias}.plugin", "", f"{kind} plugin name")
                if not isinstance(name, str) or not name:
                    raise PluginConfigurationError(
                        f"{parameter} is not set: every filter alias needs a plugin name, e.g. "
                        f"{self.FILTER_EXAMPLE}"
                    )
                try:
                    cls = load_plugin_class(self.FILTER_KIND, name, parameter)
                except (LookupError, ImportError) as exc:
                    raise PluginConfigurationError(str(exc)) from None
                instance = cls()
                try:
                    instance.initialize(self.context, f"{self.plugin_name}.{alias}")
                except PluginConfigurationError:
                    raise
                except Exception as exc:
                    raise PluginConfigurationError(
                        f"{parameter} ({name}): {type(exc).__name__}: {exc}"
                    ) from exc
                self.logger.info(f"{self.plugin_name}: loaded {kind} {alias} [{name}]")
                loaded.append((alias, instance))
        except Exception:
            for _, instance in loaded:
                instance.on_cleanup()
            raise
        return loaded

    def on_cleanup(self) -> None:
        """Release the ROS endpoints, then the filters. Configuring thread."""
        self._destroy_ros()
        self._cleanup_filters()

    def _destroy_ros(self) -> None:
        """Release the manager's ROS endpoints (subclasses that have some override this)."""

    def _cleanup_filters(self) -> None:
        filters, self._filters = self._filters, []
        for alias, instance in filters:
            try:
                instance.on_cleanup()
            except Exception as exc:  # one filter's failure must not keep the others alive
                self.logger.warning(f"{self.plugin_name}.{alias}: on_cleanup failed: {exc}")

    # -- runtime parameter changes reach the filters ------------------------------------------
    def _filter_for(self, name: str) -> tuple[Any, str] | None:
        for alias, instance in self._filters:
            if name.startswith(alias + "."):
                return instance, name[len(alias) + 1 :]
        return None

    def validate_parameter(self, name: str, value: Any) -> Any:
        """A runtime change of ``<alias>.<name>``; ``<filter>.<param>`` goes to that filter."""
        target = self._filter_for(name)
        if target is not None:
            return target[0].validate_parameter(target[1], value)
        if name == "filters" or name in self.RUNTIME_FIXED or name.endswith(".plugin"):
            raise ParameterValueError(
                f"{self.plugin_name}.{name}: cannot change at runtime (reconfigure instead)"
            )
        return super().validate_parameter(name, value)

    def apply_parameter(self, name: str, value: Any) -> None:
        """Store a validated runtime change (in the filter it belongs to)."""
        target = self._filter_for(name)
        if target is not None:
            target[0].apply_parameter(target[1], value)
            return
        super().apply_parameter(name, value)
