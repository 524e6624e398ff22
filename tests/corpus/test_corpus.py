"""The params-file corpus (issue #22): files in the original's style pass ``easynav check``.

Each ``*.params.yaml`` beside this file is written as users of the C++ original write theirs (node
sections, ``<kind>_types``, ``<alias>.plugin`` with the original's plugin strings, the original's
parameter names) and loads maps this project ships. Together they set every parameter the original's
plugins declare (easynav_plugins 0.4.2 and the related stacks) and name every plugin registered in
the entry-point groups below (README.md beside this file lists what each file covers).

The tests: each file configures (``easynav check`` exits 0); the keys ``easynav check`` reports as
unknown are exactly the known incompatibilities listed in ``KNOWN_UNKNOWN_KEYS`` (a new one is a
regression, a vanished one is a fix to record here); every registered plugin string appears in
some file; one file keeps TAB characters as in-line separators (libyaml accepts them).
"""

from __future__ import annotations

import functools
import re
import subprocess
import sys
import tempfile
from collections.abc import Iterator, Mapping
from importlib import metadata
from pathlib import Path
from typing import Any

import pytest
import yaml

pytestmark = pytest.mark.ros

CORPUS = Path(__file__).resolve().parent
EASYNAV = str(Path(sys.executable).with_name("easynav"))
FILES = sorted(CORPUS.glob("*.params.yaml"))

#: Entry-point groups whose plugin strings the corpus must name: the hosts and filters of the
#: original's catalogue, the recovery system's parts and the perception handlers.
PLUGIN_GROUPS = (
    "easynav.controllers",
    "easynav.localizers",
    "easynav.planners",
    "easynav.maps_managers",
    "easynav.recovery_managers",
    "easynav.costmap_filters",
    "easynav.routes_filters",
    "easynav.navmap_filters",
    "easynav.recovery.safety_reflexes",
    "easynav.recovery.evaluators",
    "easynav.recovery.mitigations",
    "easynav.perception_handlers",
)

#: Registered plugins the corpus leaves out on purpose, with the reason.
NOT_IN_CORPUS = {
    "easynav_playground/PerceptionEchoController":
        "a latency-benchmark instrument of easynav-playground, not a navigation plugin",
}

#: Keys of corpus files that ``easynav check`` reports as unknown: parameters the original
#: declares that this project does not accept yet (known incompatibilities, reported in issue
#: #22). Remove an entry when the plugin learns the parameter. Empty: the last ones (the fusion
#: localizer's gps0_differential, gps0_relative, imu0_twist_rejection_threshold and
#: CollisionSafetyReflex's debug_markers) are parameters now.
KNOWN_UNKNOWN_KEYS: dict[str, set[str]] = {}

_UNKNOWN = re.compile(
    r"^easynav: warning: .*?: (?P<node>[\w/]+): (?P<key>[\w.]+): unknown parameter"
)


@functools.cache
def easynav_check(path: Path) -> subprocess.CompletedProcess:
    """``easynav check`` of one file (run once per file, from a directory that is not the repo)."""
    return subprocess.run(
        [EASYNAV, "check", str(path)], capture_output=True, text=True, timeout=180,
        cwd=tempfile.gettempdir(),
    )


def unknown_keys(result: subprocess.CompletedProcess) -> set[str]:
    """``node: key`` of every "unknown parameter" warning of a check."""
    found = set()
    for line in result.stderr.splitlines():
        match = _UNKNOWN.match(line)
        if match:
            found.add(f"{match['node']}: {match['key']}")
    return found


def load(path: Path) -> Any:
    return yaml.load(path.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))  # noqa: S506


def plugin_strings(node: Any) -> Iterator[str]:
    """Every value of a key named ``plugin`` anywhere in a params document."""
    if isinstance(node, Mapping):
        for key, value in node.items():
            if key == "plugin" and isinstance(value, str):
                yield value
            else:
                yield from plugin_strings(value)
    elif isinstance(node, list):
        for item in node:
            yield from plugin_strings(item)


def registered_plugins() -> dict[str, str]:
    """Plugin string -> entry-point group, over PLUGIN_GROUPS."""
    found = {}
    for group in PLUGIN_GROUPS:
        for ep in metadata.entry_points(group=group):
            found[ep.name] = group
    return found


#: The two tests of a file run in one test process (``--dist loadgroup``): they share its
#: ``easynav check`` (a few seconds each, importing every plugin), not run it once each.
ONE_CHECK_PER_FILE = [
    pytest.param(p, id=p.name, marks=pytest.mark.xdist_group(f"corpus-{p.name}")) for p in FILES
]


def test_the_corpus_has_files_and_a_readme():
    assert len(FILES) >= 12, FILES
    readme = (CORPUS / "README.md").read_text()
    missing = [p.name for p in FILES if f"`{p.name}`" not in readme]
    assert not missing, f"README.md does not describe: {missing}"


@pytest.mark.parametrize("path", ONE_CHECK_PER_FILE)
def test_corpus_file_passes_the_check(path):
    result = easynav_check(path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "configuration OK" in result.stdout, result.stdout + result.stderr


@pytest.mark.parametrize("path", ONE_CHECK_PER_FILE)
def test_corpus_file_has_only_the_known_unknown_keys(path):
    found = unknown_keys(easynav_check(path))
    expected = KNOWN_UNKNOWN_KEYS.get(path.name, set())
    new, fixed = sorted(found - expected), sorted(expected - found)
    assert not new, f"{path.name}: keys no plugin declares any more (or typos): {new}"
    assert not fixed, (
        f"{path.name}: now accepted, remove from KNOWN_UNKNOWN_KEYS in {Path(__file__).name}: "
        f"{fixed}"
    )


def test_the_corpus_names_every_registered_plugin():
    registered = registered_plugins()
    for group in ("easynav.controllers", "easynav.localizers", "easynav.planners",
                  "easynav.maps_managers"):
        assert group in registered.values(), f"no plugin registered in {group}: wrong group name?"
    used = {name for path in FILES for name in plugin_strings(load(path))}
    missing = sorted(
        f"{name} ({group})" for name, group in registered.items()
        if name not in used and name not in NOT_IN_CORPUS
    )
    assert not missing, (
        "registered plugins that no corpus file names (add them to a file in tests/corpus, "
        f"or to NOT_IN_CORPUS with a reason): {missing}"
    )
    unregistered = sorted(used - set(registered))
    assert not unregistered, f"corpus files name plugins nobody registers: {unregistered}"


def test_a_corpus_file_has_tabs_as_separators():
    """libyaml (ROS 2's parser) accepts ``dt:<TAB>0.1``; the pure-Python scanner does not."""
    tabbed = [p for p in FILES if re.search(r"^\s*[\w/]+:\t", p.read_text(), re.MULTILINE)]
    assert tabbed, "no corpus file has a TAB after a key: keep tabs_mppi.params.yaml's tabs"
    with pytest.raises(yaml.YAMLError):
        yaml.load(tabbed[0].read_text(), Loader=yaml.SafeLoader)  # noqa: S506
