"""Generate each plugin's README tables from its declarations.

``python -m easynav.system.readme_tables`` rewrites, in the README of every distribution of
this repository, the text between::

    <!-- BEGIN generated tables: easynav_simple_controller/SimpleController -->
    <!-- END generated tables: easynav_simple_controller/SimpleController -->

with the plugin's parameter, topic and NavState tables (see
:func:`~easynav.system.plugin_reference.markdown_tables`). A plugin whose README has no
markers gets them, with its tables, appended at the end under "Plugin reference (generated)"
(move the block where it belongs: it is found by its markers). ``--check`` changes nothing and
exits 1 listing each README that differs. The test suite runs the check, so a README table
cannot drift from its declaration.
"""

from __future__ import annotations

import argparse
import inspect
import re
import sys
from dataclasses import dataclass
from pathlib import Path

from easynav.system.plugin_reference import (
    InstalledPlugin,
    declarations_of,
    installed_plugins,
    markdown_tables,
)

BEGIN = "<!-- BEGIN generated tables: {name} -->"
END = "<!-- END generated tables: {name} -->"
APPENDIX = "## Plugin reference (generated)"
COMMAND = "python -m easynav.system.readme_tables"


@dataclass
class ReadmeUpdate:
    """One README: its path, its current text and the text with every table regenerated."""

    path: Path
    old: str
    new: str
    added: list[str]


def distribution_root(cls: type) -> Path | None:
    """The source directory of the distribution defining ``cls`` (the one with pyproject.toml),
    or None for an installed (non-editable) distribution."""
    try:
        start = Path(inspect.getfile(cls)).resolve()
    except (TypeError, OSError):
        return None
    for parent in start.parents:
        if (parent / "pyproject.toml").is_file():
            return parent
        if parent.name == "site-packages":
            return None
    return None


def documented_plugins() -> list[tuple[list[InstalledPlugin], Path]]:
    """Every installed plugin class that declares parameters and whose distribution is a source
    tree here, with the README it belongs in. A class registered under several names (a renamed
    plugin keeping its old name) comes once, with all its names (sorted)."""
    by_class: dict[tuple[str, type], list[InstalledPlugin]] = {}
    for plugin in installed_plugins():
        if not declarations_of(plugin.cls):
            continue  # e.g. perception handlers: nothing declared
        by_class.setdefault((plugin.group, plugin.cls), []).append(plugin)
    result = []
    for names in by_class.values():
        root = distribution_root(names[0].cls)
        if root is not None:
            result.append((sorted(names, key=lambda p: p.name), root / "README.md"))
    return result


def _documented_name(text: str, names: list[InstalledPlugin]) -> InstalledPlugin:
    # The name whose block the README has, else the first name.
    for plugin in names:
        if BEGIN.format(name=plugin.name) in text:
            return plugin
    return names[0]


def block(plugin: InstalledPlugin) -> str:
    """The marked block of one plugin."""
    return "\n".join((
        BEGIN.format(name=plugin.name),
        "",
        markdown_tables(plugin.cls),
        "",
        END.format(name=plugin.name),
    ))


def regenerate(text: str, plugins: list[InstalledPlugin]) -> tuple[str, list[str]]:
    """``text`` with each plugin's block replaced (or appended); the names appended."""
    added = []
    for plugin in plugins:
        begin, end = BEGIN.format(name=plugin.name), END.format(name=plugin.name)
        pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
        generated = block(plugin)
        if pattern.search(text):
            text = pattern.sub(lambda _m, g=generated: g, text, count=1)
            continue
        if APPENDIX not in text:
            text = text.rstrip("\n") + f"\n\n{APPENDIX}\n"
        text = text.rstrip("\n") + f"\n\n### `{plugin.name}`\n\n{generated}\n"
        added.append(plugin.name)
    return text, added


class _NodeParameters:
    """EasyNav's own nodes' parameters, tabled like a plugin's (in easynav-system's README)."""

    def __init__(self, declarations: tuple) -> None:
        self._declarations = tuple(declarations)

    def parameter_declarations(self) -> tuple:
        return self._declarations


def node_tables() -> list[InstalledPlugin]:
    """The node-level tables: ``controller_node``, ``system_node``, ``system_node.safety``,
    ``sensors_node``."""
    from dataclasses import replace

    from easynav.system.node_declarations import (
        CONTROLLER_NODE_PARAMETERS,
        SAFETY_PARAMETERS,
        SYSTEM_PARAMETERS,
    )
    from easynav.system.sensors.sensor_parameters import SENSOR_PARAMETERS, SENSORS_NODE_PARAMETERS

    sensors = SENSORS_NODE_PARAMETERS + tuple(
        replace(p, name=f"<id>.{p.name}") for p in SENSOR_PARAMETERS
    )

    return [
        InstalledPlugin(name, "", "easynav-system", _NodeParameters(declarations))
        for name, declarations in (
            ("controller_node", CONTROLLER_NODE_PARAMETERS),
            ("system_node", SYSTEM_PARAMETERS),
            ("system_node.safety", SAFETY_PARAMETERS),
            ("sensors_node", sensors),
        )
    ]


def updates() -> list[ReadmeUpdate]:
    """The regenerated text of every README that documents a plugin."""
    by_readme: dict[Path, list[list[InstalledPlugin]]] = {}
    system_readme = Path(__file__).resolve().parents[3] / "README.md"
    if system_readme.is_file():
        by_readme[system_readme] = [[table] for table in node_tables()]
    for names, readme in documented_plugins():
        by_readme.setdefault(readme, []).append(names)
    result = []
    for readme, classes in sorted(by_readme.items()):
        old = readme.read_text() if readme.is_file() else f"# {readme.parent.name}\n"
        new, added = regenerate(old, [_documented_name(old, names) for names in classes])
        result.append(ReadmeUpdate(readme, old, new, added))
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog=COMMAND, description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="change nothing; exit 1 on a diff")
    args = parser.parse_args(argv)
    stale = 0
    for update in updates():
        if update.new == update.old:
            continue
        stale += 1
        if args.check:
            missing = f" (no markers for {', '.join(update.added)})" if update.added else ""
            print(f"{update.path}: tables differ from the declarations{missing}")
        else:
            update.path.write_text(update.new)
            print(f"{update.path}: tables regenerated")
    if args.check and stale:
        print(f"run: {COMMAND}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
