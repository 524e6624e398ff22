"""Which plugins can work together: map representations provided and needed, declared by plugins.

"The localizer and planner are usually tightly coupled to the representation defined by the maps
manager": SimplePlanner reads a SimpleMap under NavState ``map``, CostmapPlanner a Costmap2D under
the same key. Each maps manager declares the representations it writes (``PROVIDES_MAPS``), each
localizer, planner or controller the representations it can work on (``NEEDS_MAPS``: any one of
them; empty when it needs no map). A combination where a plugin needs a representation that no
loaded maps manager provides is rejected at configure time (so by ``easynav check``), naming both
sides, instead of a planner that silently never plans.

Representation names used by the catalogue: ``simple_map`` (SimpleMap), ``costmap``
(Costmap2D), ``octomap``, ``bonxai``, ``navmap``, ``gridmap``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

#: (alias, plugin name, plugin class) of each plugin a node loaded.
LoadedEntry = tuple[str, str, type]


def provided_maps(cls: type) -> tuple[str, ...]:
    """The map representations a plugin class writes to NavState."""
    return tuple(getattr(cls, "PROVIDES_MAPS", ()))


def needed_maps(cls: type) -> tuple[str, ...]:
    """The map representations a plugin class can work on (any one); empty: none needed."""
    return tuple(getattr(cls, "NEEDS_MAPS", ()))


def compatible(needs: Iterable[str], provides: Iterable[str]) -> bool:
    """Whether a plugin needing ``needs`` can run beside maps providing ``provides``."""
    needs = tuple(needs)
    return not needs or bool(set(needs) & set(provides))


def compatibility_errors(loaded: Mapping[str, Iterable[LoadedEntry]]) -> list[str]:
    """One message per loaded plugin whose needed map no loaded maps manager provides.

    ``loaded`` maps each node name to the ``(alias, plugin name, class)`` it loaded.
    """
    providers = [
        (node, alias, name, provided_maps(cls))
        for node, entries in loaded.items()
        for alias, name, cls in entries
        if provided_maps(cls)
    ]
    provided = {rep for *_, reps in providers for rep in reps}
    errors = []
    for node, entries in loaded.items():
        for alias, name, cls in entries:
            needs = needed_maps(cls)
            if compatible(needs, provided):
                continue
            if providers:
                offer = "; ".join(
                    f"{n}.{a} [{p}] provides {', '.join(reps)}" for n, a, p, reps in providers
                )
            else:
                offer = "no loaded maps manager provides a map"
            errors.append(
                f"{node}.{alias} [{name}] needs a map of type {' or '.join(needs)}, but {offer}"
            )
    return errors
