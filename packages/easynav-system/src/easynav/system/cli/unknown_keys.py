"""Keys of a params file that nothing declares (``easynav check``): likely typos.

Checked: every key under a plugin's namespace (``<alias>.*`` of the aliases listed in
``controller_types``, ``localizer_types``, ``planner_types``, ``map_types`` and
``recovery_manager.*``), against the plugin's declarations (current and deprecated names, and
``plugin``; a plugin hosting sub-plugins checks theirs too), and the node-level groups that
EasyNav declares (``controller_node.robot_limits.*``, ``system_node.robot_geometry.*``,
``system_node.safety.*``). Plugins that are not installed are not checked (configure reports
them). Nothing here needs ROS.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from easynav.core.plugins.declarations import declared_names
from easynav.core.plugins.discovery import load_plugin_class
from easynav.core.plugins.parameter_owner import closest_name
from easynav.core.plugins.plugin_kinds import (
    CONTROLLER,
    LOCALIZER,
    MAPS_MANAGER,
    PLANNER,
    RECOVERY_MANAGER,
    PluginKind,
)
from easynav.system.cli.params_file import _node_entries
from easynav.system.node_declarations import (
    CONTROLLER_NODE_PARAMETERS,
    SAFETY_PARAMETERS,
    SYSTEM_PARAMETERS,
)

#: Host nodes: the list of plugin aliases and the kind of plugin they load.
PLUGIN_LISTS: dict[str, tuple[str, PluginKind]] = {
    "controller_node": ("controller_types", CONTROLLER),
    "localizer_node": ("localizer_types", LOCALIZER),
    "planner_node": ("planner_types", PLANNER),
    "maps_manager_node": ("map_types", MAPS_MANAGER),
}


@dataclass(frozen=True)
class UnknownKey:
    """A key no declaration knows, with the closest declared name (or None)."""

    node: str
    key: str
    suggestion: str | None

    def message(self) -> str:
        """``simple.look_ahed_dist: unknown parameter, did you mean look_ahead_dist?``"""
        text = f"{self.node}: {self.key}: unknown parameter"
        if self.suggestion:
            return f"{text}, did you mean {self.suggestion.rsplit('.', 1)[-1]}?"
        return text


def flatten(parameters: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested YAML mappings as dotted keys (``{"a": {"b": 1}}`` → ``{"a.b": 1}``)."""
    flat: dict[str, Any] = {}
    for key, value in parameters.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(flatten(value, f"{name}."))
        else:
            flat[name] = value
    return flat


def _under(flat: Mapping[str, Any], prefix: str) -> dict[str, Any]:
    return {k[len(prefix) + 1:]: v for k, v in flat.items() if k.startswith(prefix + ".")}


def _plugin_unknowns(
    node: str, alias: str, kind: PluginKind, keys: dict[str, Any], default_plugin: str = ""
) -> Iterator[UnknownKey]:
    name = keys.get("plugin", default_plugin)
    try:
        cls = load_plugin_class(kind, str(name), f"{node}.{alias}.plugin")
    except Exception:  # not installed or not set: configure says so, naming the parameter
        return
    finder = getattr(cls, "unknown_parameter_keys", None)
    if finder is None:
        return
    for key, suggestion in finder(keys):
        full_suggestion = None if suggestion is None else f"{alias}.{suggestion}"
        yield UnknownKey(node, f"{alias}.{key}", full_suggestion)


def _group_unknowns(
    node: str, flat: Mapping[str, Any], group: str, declarations: Any
) -> Iterator[UnknownKey]:
    known = declared_names(declarations)
    for key in flat:
        if key.startswith(group + ".") and key not in known:
            yield UnknownKey(node, key, closest_name(key, known))


def unknown_keys(document: Mapping[str, Any]) -> list[UnknownKey]:
    """Every key of a loaded params file (see ``load_params_file``) that nothing declares."""
    found: list[UnknownKey] = []
    for qualified, entry in _node_entries(dict(document)):
        node = qualified.rsplit("/", 1)[-1]
        parameters = entry.get("ros__parameters") if isinstance(entry, Mapping) else None
        if not isinstance(parameters, Mapping):
            continue
        flat = flatten(parameters)
        label = qualified
        if node in PLUGIN_LISTS:
            list_name, kind = PLUGIN_LISTS[node]
            aliases = flat.get(list_name) or []
            for alias in aliases if isinstance(aliases, list) else []:
                found += _plugin_unknowns(label, str(alias), kind, _under(flat, str(alias)))
        elif node == "recovery_node":
            found += _plugin_unknowns(
                label, "recovery_manager", RECOVERY_MANAGER, _under(flat, "recovery_manager"),
                "easynav_recovery/DummyRecoveryManager",
            )
        if node == "controller_node":
            found += _group_unknowns(label, flat, "robot_limits", CONTROLLER_NODE_PARAMETERS)
        if node == "system_node":
            found += _group_unknowns(label, flat, "robot_geometry", SYSTEM_PARAMETERS)
            found += _group_unknowns(label, flat, "safety", SAFETY_PARAMETERS)
    return found
