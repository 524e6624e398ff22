"""The demo's derived params for the NavMap stack: the world's mesh, wall cloud and start floor.

:func:`~easynav.playground.demo.params_patch.derive_params` points the 2D maps managers and the
initial pose at the world run; :func:`point_navmap_stack_at_world` does the same, on the file it
wrote, for the NavMap stack (issue #17):

- every ``NavMapMapsManager`` alias loads the world's walkable-surface mesh
  (``<world>.walkable.ply`` beside a multi-level world's description; ``navmap_path_file``,
  ``package`` and ``occmap_path_file`` emptied), or, on a world without levels, converts its
  map-server map (``occmap_path_file``);
- every ``BonxaiMapsManager`` alias of a multi-level world loads its wall cloud
  (``<world>.walls.ply`` beside the description, generated into the run directory by
  :mod:`easynav.playground.sim.wall_cloud` when the world ships none) instead of extruding the
  ground floor's 2D map;
- every NavMap ``InflationFilter`` inflates at least as far as the world's robot reaches: its
  ``inflation_radius`` is raised to the robot's radius when smaller (cost 253 reaches the
  robot geometry's inscribed radius, at least the world's robot in the demo, only within the
  inflation radius);
- every localizer alias with an ``initial_pose`` gets ``initial_pose.z``, the start floor's
  height, when the world has levels and the alias declares that key (the NavMap AMCL).

:func:`goal_height` gives the height of a waypoint on its level, for the goal sent.

Thread contract: plain functions, main thread.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from easynav.playground.demo.params_patch import _get, _ros_parameters, _set
from easynav.playground.sim.wall_cloud import wall_cloud_path, write_wall_cloud

NAVMAP_MAPS_MANAGERS = ("easynav_navmap_maps_manager/NavMapMapsManager",)
NAVMAP_INFLATION_FILTER = "easynav_navmap_maps_manager/NavMapMapsManager/InflationFilter"
#: The NavMap InflationFilter's default inflation radius (the original's).
NAVMAP_INFLATION_RADIUS = 0.30
BONXAI_MAPS_MANAGERS = ("easynav_bonxai_maps_manager/BonxaiMapsManager",)


def walkable_mesh_path(description) -> Path | None:
    """The walkable-surface mesh of a multi-level world (``<stem>.walkable.ply`` beside its
    description), None for a world without levels or without the file."""
    if description.levels is None or not description.source:
        return None
    source = Path(description.source)
    path = source.with_name(f"{source.stem}.walkable.ply")
    return path.resolve() if path.is_file() else None


def wall_cloud_file(description, run_dir: Path) -> Path | None:
    """The wall cloud of a multi-level world: the shipped ``<stem>.walls.ply``, else one
    generated into ``run_dir``; None for a world without levels."""
    if description.levels is None or not description.source:
        return None
    shipped = wall_cloud_path(description.source)
    if shipped.is_file():
        return shipped.resolve()
    return write_wall_cloud(description.source, Path(run_dir) / shipped.name).resolve()


def start_height(description) -> float | None:
    """Height of the start pose on the world's start level (None: a world without levels)."""
    levels = description.make_levels()
    if levels is None:
        return None
    x, y, _ = description.start_pose
    return levels.height(levels.start_level, x, y)


def goal_height(description, waypoint) -> float:
    """Height (m) of ``waypoint`` (a :class:`WaypointResult`) on its level; 0 when the world or
    the waypoint has no level."""
    level = getattr(waypoint, "level", None)
    if description.levels is None or level is None:
        return 0.0
    return description.make_levels().height(level, waypoint.x, waypoint.y)


def _inflate_for_robot(maps: dict, alias: str, radius: float) -> dict[str, str]:
    """Raise the inflation radius of ``alias``'s NavMap InflationFilters to ``radius`` where
    smaller; the notes, keyed by the filter's parameter prefix."""
    notes = {}
    for name in _get(maps, f"{alias}.filters", []) or []:
        if _get(maps, f"{alias}.{name}.plugin") != NAVMAP_INFLATION_FILTER:
            continue
        key = f"{alias}.{name}.inflation_radius"
        value = float(_get(maps, key, NAVMAP_INFLATION_RADIUS))
        if value < radius:
            _set(maps, key, float(radius))
            prefix = f"maps_manager_node.{alias}.{name} "
            notes[prefix] = (f"{prefix}inflation_radius {value:g} -> {radius:g}: the world's "
                             f"robot is {radius:g} m")
    return notes


def point_navmap_stack_at_world(derived: Path, description, map_yaml: Path | None,
                                notes: list[str]) -> list[str]:
    """Rewrite the derived params file ``derived`` for the NavMap stack (see the module
    documentation). Returns ``notes`` with the notes of the aliases rewritten here replaced."""
    params = yaml.safe_load(Path(derived).read_text())
    if not isinstance(params, dict):
        return notes
    run_dir = Path(derived).parent
    new_notes: dict[str, str] = {}
    maps = _ros_parameters(params, "maps_manager_node") or {}
    mesh = walkable_mesh_path(description)
    for alias in maps.get("map_types", []) or []:
        plugin = _get(maps, f"{alias}.plugin")
        prefix = f"maps_manager_node.{alias} "
        if plugin in NAVMAP_MAPS_MANAGERS and mesh is not None:
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.occmap_path_file", "")
            _set(maps, f"{alias}.navmap_path_file", str(mesh))
            new_notes[prefix] = f"{prefix}loads the world's walkable-surface mesh {mesh}"
        elif plugin in NAVMAP_MAPS_MANAGERS and map_yaml is not None:
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.navmap_path_file", "")
            _set(maps, f"{alias}.occmap_path_file", str(map_yaml))
            new_notes[prefix] = f"{prefix}converts the world's map {map_yaml} to a NavMap"
        elif plugin in BONXAI_MAPS_MANAGERS and description.levels is not None:
            cloud = wall_cloud_file(description, run_dir)
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.occmap_path_file", "")
            _set(maps, f"{alias}.bonxai_path_file", str(cloud))
            new_notes[prefix] = f"{prefix}loads the world's wall cloud {cloud}"
        if plugin in NAVMAP_MAPS_MANAGERS and description.robot.declared:
            new_notes.update(_inflate_for_robot(maps, alias, description.robot.radius))
    localizer = _ros_parameters(params, "localizer_node") or {}
    z = start_height(description)
    if z is not None:
        for alias in localizer.get("localizer_types", []) or []:
            if _get(localizer, f"{alias}.initial_pose.z") is not None:
                _set(localizer, f"{alias}.initial_pose.z", float(z))
                key = f"localizer_node.{alias}.initial_pose.z "
                new_notes[key] = f"{key}= {z:.2f}, the start floor's height"
    if not new_notes:
        return notes
    Path(derived).write_text(yaml.safe_dump(params, sort_keys=False))
    kept = [n for n in notes if not any(n.startswith(p) for p in new_notes)]
    return kept + list(new_notes.values())
