"""Every README table of plugin (and node) parameters is what the declarations generate.

It covers the plugins of every installed distribution of this repository: a plugin added by
any package is checked once installed, and one whose README has no generated block fails.
"""

from __future__ import annotations

import difflib
import importlib.util

import pytest

from easynav.core.dummy import DummyController
from easynav.system.readme_tables import (
    COMMAND,
    distribution_root,
    documented_plugins,
    updates,
)

# Installed from wheels (an isolated install), there is no README to compare with.
pytestmark = pytest.mark.skipif(
    distribution_root(DummyController) is None, reason="easynav-core is not a source tree"
)


def test_every_plugin_with_declarations_is_found():
    names = {plugin.name for group, _ in documented_plugins() for plugin in group}
    assert "easynav_controller/DummyController" in names
    # Other distributions' plugins, when installed (setup installs every package; an isolated
    # install of the kernel has only its own).
    if importlib.util.find_spec("easynav.controllers") is not None:
        assert "easynav_simple_controller/SimpleController" in names


def test_readme_tables_match_the_declarations():
    problems = []
    for update in updates():
        if update.added:
            problems.append(
                f"{update.path} has no generated tables for {', '.join(update.added)}: run "
                f"`{COMMAND}` (it appends them under 'Plugin reference (generated)'; move the "
                f"marked block where it belongs)"
            )
        elif update.new != update.old:
            diff = "\n".join(difflib.unified_diff(
                update.old.splitlines(), update.new.splitlines(), str(update.path),
                "generated", lineterm="", n=1,
            ))
            problems.append(
                f"{update.path}: tables differ from the declarations; run `{COMMAND}`\n{diff}"
            )
    assert not problems, "\n\n".join(problems)
