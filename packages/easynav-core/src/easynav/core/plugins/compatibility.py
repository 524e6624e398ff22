"""Which plugins can work together: map representations provided and needed, declared by plugins.

"The localizer and planner are usually tightly coupled to the representation defined by the maps
manager": SimplePlanner reads a SimpleMap under NavState ``map``, CostmapPlanner a Costmap2D under
the same key. Each maps manager declares the representations it writes (``PROVIDES_MAPS``), each
localizer, planner or controller the representations it can work on (``NEEDS_MAPS``: any one of
them; empty when it needs no map) and those it needs besides, every one (``REQUIRES_MAPS``). A
combination where a plugin needs a representation that no
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


def required_maps(cls: type) -> tuple[str, ...]:
    """The map representations a plugin class needs besides, every one of them."""
    return tuple(getattr(cls, "REQUIRES_MAPS", ()))


def compatible(needs: Iterable[str], provides: Iterable[str], requires: Iterable[str] = ()) -> bool:
    """Whether a plugin needing one of ``needs`` and all of ``requires`` can run beside maps
    providing ``provides``."""
    needs, provides = tuple(needs), set(provides)
    return (not needs or bool(set(needs) & provides)) and set(requires) <= provides


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
            needs, requires = needed_maps(cls), required_maps(cls)
            if compatible(needs, provided, requires):
                continue
            if providers:
                offer = "; ".join(
                    f"{n}.{a} [{p}] provides {', '.join(reps)}" for n, a, p, reps in providers
                )
            else:
                offer = "no loaded maps manager provides a map"
            if not compatible(needs, provided):
                wanted = f"a map of type {' or '.join(needs)}"
            else:
                wanted = "maps of types " + " and ".join(r for r in requires if r not in provided)
            errors.append(f"{node}.{alias} [{name}] needs {wanted}, but {offer}")
    return errors
