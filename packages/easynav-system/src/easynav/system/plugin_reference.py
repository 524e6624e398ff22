"""What users see of a plugin's declarations: ``easynav plugins --describe`` and README tables.

Both are made from the plugin class's ``PARAMETERS``, ``TOPICS``, ``READS`` and ``WRITES``
(nothing is written by hand), so they cannot drift from the code.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import metadata
from typing import Any

from easynav.core.plugins.declarations import Param
from easynav.core.plugins.discovery import PluginLoadError, _entry_points, load_plugin_class
from easynav.core.plugins.plugin_kinds import ALL_KINDS, PluginKind


@dataclass(frozen=True)
class InstalledPlugin:
    """An installed plugin: its name, entry-point group, providing distribution and class."""

    name: str
    group: str
    distribution: str
    cls: type


def _groups() -> list[str]:
    core = [k.entry_point_group for k in ALL_KINDS]
    others = sorted(
        g for g in metadata.entry_points().groups
        if g.startswith("easynav.") and g not in core and g != "easynav.map_packages"
    )
    return core + others


def installed_plugins() -> list[InstalledPlugin]:
    """Every installed plugin of every ``easynav.*`` entry-point group, imported.

    Raises :class:`PluginLoadError` for the first one that fails to import.
    """
    plugins = []
    for group in _groups():
        kind = PluginKind(group, group, object, "")
        for ep in _entry_points(group):
            cls = load_plugin_class(kind, ep.name, f"{group}:{ep.name}")
            dist = ep.dist.metadata["Name"] if ep.dist else "?"
            plugins.append(InstalledPlugin(ep.name, group, dist, cls))
    # Stable: plugins of one class keep their entry-point order (the first name is canonical).
    return sorted(plugins, key=lambda p: p.distribution)


def find_plugin(name: str) -> InstalledPlugin:
    """The installed plugin called ``name`` (``easynav_simple_controller/SimpleController``).

    Raises ``LookupError`` naming the installed plugins with the closest names.
    """
    for group in _groups():
        for ep in _entry_points(group):
            if ep.name == name:
                kind = PluginKind(group, group, object, "")
                cls = load_plugin_class(kind, name, f"{group}:{name}")
                dist = ep.dist.metadata["Name"] if ep.dist else "?"
                return InstalledPlugin(name, group, dist, cls)
    import difflib

    names = sorted({ep.name for group in _groups() for ep in _entry_points(group)})
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.4)
    hint = f" Did you mean {', '.join(close)}?" if close else ""
    raise LookupError(f"no installed plugin is called '{name}'.{hint}")


def declarations_of(cls: Any) -> tuple[Param, ...]:
    """A plugin class's parameter declarations (none for classes that declare nothing)."""
    declarations = getattr(cls, "parameter_declarations", None)
    return tuple(declarations()) if declarations is not None else ()


# -- cells -------------------------------------------------------------------------------------
def _type_cell(param: Param) -> str:
    return param.type


def _description_cell(param: Param) -> str:
    text = param.description
    notes = []
    if param.deprecated:
        notes.append("replaces " + ", ".join(f"`{old}`" for old in param.deprecated))
    if not param.dynamic:
        notes.append("read at configure")
    if notes:
        text += f" ({'; '.join(notes)})"
    return text


def parameter_rows(declarations: tuple[Param, ...]) -> list[tuple[str, str, str, str, str, str]]:
    """``(name, type, default, unit, range, description)`` of each parameter."""
    return [
        (p.name, _type_cell(p), p.describe_default(), p.unit, p.rule(), _description_cell(p))
        for p in declarations
    ]


def _md_escape(text: str) -> str:
    return text.replace("|", "\\|")


def markdown_tables(cls: Any) -> str:
    """The parameter, topic and NavState tables of a plugin class, in Markdown."""
    lines = [
        "| Parameter | Type | Default | Unit | Range | Description |",
        "|---|---|---|---|---|---|",
    ]
    for name, kind, default, unit, rule, description in parameter_rows(declarations_of(cls)):
        cells = (f"`{name}`", kind, f"`{default}`", unit, rule, description)
        lines.append("| " + " | ".join(_md_escape(c) for c in cells) + " |")
    topics = getattr(cls, "TOPICS", ())
    if topics:
        lines += [
            "",
            "| Topic | Message | Direction | QoS | Description |",
            "|---|---|---|---|---|",
        ]
        for t in topics:
            cells = (f"`{t.name}`", f"`{t.message_type}`", t.direction, t.qos, t.description)
            lines.append("| " + " | ".join(_md_escape(c) for c in cells) + " |")
    keys = [(k, "read") for k in getattr(cls, "READS", ())]
    keys += [(k, "write") for k in getattr(cls, "WRITES", ())]
    if keys:
        lines += ["", "| NavState key | Type | Access | Description |", "|---|---|---|---|"]
        for key, access in keys:
            cells = (
                f"`{key}`",
                f"`{getattr(key, 'value_type', '')}`",
                access,
                getattr(key, "description", ""),
            )
            lines.append("| " + " | ".join(_md_escape(c) for c in cells) + " |")
    return "\n".join(lines)


def describe_text(plugin: InstalledPlugin) -> str:
    """``easynav plugins --describe NAME``: parameters, topics, NavState keys, as text."""
    cls = plugin.cls
    out = [f"{plugin.name}  ({cls.__module__}.{cls.__qualname__}, {plugin.distribution})", ""]
    rows = parameter_rows(declarations_of(cls))
    header = ("name", "type", "default", "unit", "range", "description")
    out.append("Parameters (under <alias>.):")
    widths = [max(len(header[i]), *(len(r[i]) for r in rows)) for i in range(5)] if rows else []
    for row in [header, *rows] if rows else []:
        cells = (c.ljust(w) for c, w in zip(row[:5], widths, strict=True))
        out.append("  " + "  ".join(cells) + "  " + row[5])
    topics = getattr(cls, "TOPICS", ())
    out += ["", "Topics:"]
    out += [
        f"  {t.direction:<4} {t.name}  [{t.message_type}, {t.qos}]"
        + (f"  {t.description}" if t.description else "")
        for t in topics
    ] or ["  (none)"]
    for title, keys in (("NavState keys read:", "READS"), ("NavState keys written:", "WRITES")):
        out += ["", title]
        out += [
            f"  {key}  [{getattr(key, 'value_type', '')}]  {getattr(key, 'description', '')}"
            for key in getattr(cls, keys, ())
        ] or ["  (none)"]
    return "\n".join(out)


__all__ = [
    "InstalledPlugin",
    "PluginLoadError",
    "declarations_of",
    "describe_text",
    "find_plugin",
    "installed_plugins",
    "markdown_tables",
    "parameter_rows",
]
