"""The catalogue names the distribution of every installed plugin of the main kinds."""

from __future__ import annotations

from importlib.metadata import entry_points

from easynav.core.plugins.catalogue import CATALOGUE
from easynav.core.plugins.plugin_kinds import ALL_KINDS, PERCEPTION_HANDLER

#: Map filters are named in params files too (``<alias>.<filter>.plugin``).
FILTER_GROUPS = ("easynav.costmap_filters", "easynav.navmap_filters", "easynav.routes_filters")
#: Plugins for this project's own tests and demos, never named in a user's params file.
INTERNAL_DISTRIBUTIONS = ("easynav-playground",)


def test_every_installed_plugin_is_catalogued_with_its_distribution():
    groups = [k.entry_point_group for k in ALL_KINDS if k is not PERCEPTION_HANDLER]
    missing, wrong = [], []
    for group in (*groups, *FILTER_GROUPS):
        for ep in entry_points(group=group):
            dist = ep.dist.name if ep.dist is not None else None
            if dist in INTERNAL_DISTRIBUTIONS:
                continue
            if ep.name not in CATALOGUE:
                missing.append(f"{ep.name} ({dist})")
            elif dist is not None and CATALOGUE[ep.name] != dist:
                wrong.append(f"{ep.name}: catalogue {CATALOGUE[ep.name]}, installed from {dist}")
    # The catalogue tells a user which package to install for a plugin a params file names.
    assert not missing, f"not in easynav.core.plugins.catalogue: {missing}"
    assert not wrong, wrong
