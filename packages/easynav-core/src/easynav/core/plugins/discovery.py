"""Plugin discovery through entry points, one group per kind, by the original plugin names.

Listing reads distribution metadata only (nothing is imported, as napari's manifests do), so
``easynav plugins`` and ``easynav check`` stay fast and a broken package cannot hide the others.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import metadata

from easynav.core.plugins.catalogue import CATALOGUE
from easynav.core.plugins.plugin_kinds import ALL_KINDS, PluginKind


class PluginNotFoundError(LookupError):
    """A params file names a plugin that no installed distribution provides."""


class PluginLoadError(ImportError):
    """A plugin's entry point exists but its module failed to import or is not a valid plugin."""


@dataclass(frozen=True)
class PluginInfo:
    """One installed plugin: its name, kind, target and providing distribution."""

    name: str
    kind: PluginKind
    target: str
    distribution: str
    version: str


def _entry_points(group: str) -> list[metadata.EntryPoint]:
    return list(metadata.entry_points(group=group))


def list_plugins(kind: PluginKind | None = None) -> list[PluginInfo]:
    """Every installed plugin (of ``kind``, or of every kind), without importing any."""
    infos = []
    for k in (kind,) if kind else ALL_KINDS:
        for ep in _entry_points(k.entry_point_group):
            dist = ep.dist
            infos.append(
                PluginInfo(
                    name=ep.name,
                    kind=k,
                    target=ep.value,
                    distribution=dist.metadata["Name"] if dist else "?",
                    version=dist.version if dist else "?",
                )
            )
    return sorted(infos, key=lambda i: (i.kind.name, i.name))


def other_plugin_groups() -> dict[str, list[PluginInfo]]:
    """Plugins of kinds that packages define themselves (entry-point groups ``easynav.*`` that
    are not core kinds, e.g. the diagnostic recovery's evaluators), by group; not imported.
    """
    core_groups = {k.entry_point_group for k in ALL_KINDS} | {"easynav.map_packages"}
    groups: dict[str, list[PluginInfo]] = {}
    for group in sorted(metadata.entry_points().groups):
        if not group.startswith("easynav.") or group in core_groups:
            continue
        kind = PluginKind(group.removeprefix("easynav.").replace("_", " "), group, object, "")
        for ep in _entry_points(group):
            dist = ep.dist
            groups.setdefault(group, []).append(
                PluginInfo(
                    name=ep.name,
                    kind=kind,
                    target=ep.value,
                    distribution=dist.metadata["Name"] if dist else "?",
                    version=dist.version if dist else "?",
                )
            )
    return {g: sorted(infos, key=lambda i: i.name) for g, infos in groups.items()}


def plugin_exists(kind: PluginKind, name: str) -> bool:
    """True when an installed distribution registers ``name`` in ``kind``'s group."""
    return any(ep.name == name for ep in _entry_points(kind.entry_point_group))


def not_found_message(kind: PluginKind, name: str, parameter: str) -> str:
    """The error for an unknown plugin name: what is installed and which package to install."""
    installed = sorted({ep.name for ep in _entry_points(kind.entry_point_group)})
    message = f"{parameter}: unknown {kind.name} plugin '{name}'."
    provider = CATALOGUE.get(name)
    if provider:
        try:
            installed_version = metadata.version(provider)
        except metadata.PackageNotFoundError:
            message += (
                f" It is provided by the '{provider}' distribution, which is not installed: "
                f"pip install {provider}."
            )
        else:
            message += (
                f" It belongs to the '{provider}' distribution, but the installed "
                f"{provider} {installed_version} does not provide it."
            )
    else:
        other = [k.name for k in ALL_KINDS if k is not kind and plugin_exists(k, name)]
        if other:
            message += f" '{name}' is a {other[0]} plugin, not a {kind.name} plugin."
    message += f" Installed {kind.name} plugins: {', '.join(installed) if installed else 'none'}."
    return message


def load_plugin_class(kind: PluginKind, name: str, parameter: str) -> type:
    """The class registered as ``name`` for ``kind``.

    Raises :class:`PluginNotFoundError` (names the parameter, lists installed plugins and the
    distribution to install) or :class:`PluginLoadError` (the module failed to import or the
    class does not derive from the kind's base class).
    """
    matches = [ep for ep in _entry_points(kind.entry_point_group) if ep.name == name]
    if not matches:
        raise PluginNotFoundError(not_found_message(kind, name, parameter))
    ep = matches[0]
    try:
        cls = ep.load()
    except Exception as exc:
        dist = ep.dist.metadata["Name"] if ep.dist else "?"
        raise PluginLoadError(
            f"{parameter}: plugin '{name}' from distribution '{dist}' failed to import "
            f"({ep.value}): {type(exc).__name__}: {exc}"
        ) from exc
    if kind.base_class is not object and not (
        isinstance(cls, type) and issubclass(cls, kind.base_class)
    ):
        raise PluginLoadError(
            f"{parameter}: plugin '{name}' ({ep.value}) is not a {kind.base_class.__name__}"
        )
    return cls


def check_imports() -> list[str]:
    """Import every installed plugin; one message per plugin that fails (others still listed)."""
    problems = []
    for info in list_plugins():
        try:
            load_plugin_class(info.kind, info.name, f"{info.kind.entry_point_group}:{info.name}")
        except PluginLoadError as exc:
            problems.append(str(exc))
    return problems
