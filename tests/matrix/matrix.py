"""The integration test matrix: every compatible combination of navigation plugins × world.

The combinations come from what is installed and what the plugins declare, never from a list
written here: every maps manager, localizer, planner and controller registered by a navigation
distribution (the kernel's Dummy plugins, the fault injectors and the playground's instruments
are not navigation plugins), kept when each plugin's needed map representation
(``NEEDS_MAPS``) is one the maps manager provides (``PROVIDES_MAPS``). A new plugin joins the
matrix by being installed.

Each plugin runs with its representative configuration (:func:`representative_sections`): its
section in a params file under ``params/`` written for the row's world (its ``# Run: ...
--world NAME`` line), else in the playground's file, else in the first file that uses it (every
plugin ships one); a maps stack of two managers takes both sections from a file that stacks
them. The rest (robot limits and geometry, recovery) is the playground's own params file, with
the sensors the chosen plugins read added from their files. A run is one waypoint mission of
the playground demo (``run_demo``); its figures come from the demo's ``summary.json``.

CI runs :func:`ci_slice`: the combinations that together use every plugin, each in the first
world that suits it, on the first :data:`SLICE_TOUR_METRES` of that world's tour.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import io
import itertools
import json
import math
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from easynav.core.plugins.compatibility import (
    compatible,
    needed_maps,
    provided_maps,
    required_maps,
)
from easynav.core.plugins.discovery import list_plugins, load_plugin_class
from easynav.core.plugins.plugin_kinds import ALL_KINDS
from easynav.system.cli.params_file import load_ros_yaml

ROOT = Path(__file__).resolve().parents[2]
PARAMS_DIR = ROOT / "params"
BASE_PARAMS = PARAMS_DIR / "playground.params.yaml"
#: The failures that were looked into, with their causes (see :class:`Finding`).
FINDINGS = Path(__file__).resolve().with_name("findings.yaml")

#: Distributions whose plugins are not navigation plugins (Dummy plugins, fault injectors, the
#: playground's measuring instruments).
NOT_NAVIGATION = {"easynav-core", "easynav-faulty", "easynav-playground"}

#: The matrix's four axes: (node, types parameter, plugin kind name), in the order of a row.
AXES = (
    ("maps_manager_node", "map_types", "maps manager"),
    ("localizer_node", "localizer_types", "localizer"),
    ("planner_node", "planner_types", "planner"),
    ("controller_node", "controller_types", "controller"),
)
#: Shipped worlds a combination runs in, by default: the home world, the real maps and the
#: outdoor campus (the only one with a GNSS receiver).
WORLDS = ("home", "tb3_sandbox", "depot", "campus")


@dataclass(frozen=True)
class Combination:
    """One plugin of each axis and a world. ``maps_manager`` may be a stack: a maps manager
    and one that works on its map (``a+b``, e.g. the costmap and the routes on it)."""

    maps_manager: str
    localizer: str
    planner: str
    controller: str
    world: str

    @property
    def maps_managers(self) -> tuple[str, ...]:
        return tuple(self.maps_manager.split("+"))

    @property
    def plugins(self) -> tuple[str, ...]:
        return (*self.maps_managers, self.localizer, self.planner, self.controller)

    @property
    def name(self) -> str:
        short = [p.split("/")[0].removeprefix("easynav_") for p in self.plugins]
        return "-".join(short) + f"@{self.world}"


#: A localisation error above this at any time of a run (from its first estimate) fails its row,
#: whatever the mission's end: the robot was lost, and a user sees it. The rows of the current code
#: stay under 1 m (GNSS on the campus the least accurate, 0.93 m at most; GNSS rows from before
#: the GpsLocalizer carried its pose through outages reached 7.4 m); MH-AMCL on the campus reached
#: all 5 waypoints while 88 m off.
LOST_LOCALISATION = 2.0  # m


def localisation_lost(summary: dict) -> bool:
    """True when a run's localisation error ever exceeded :data:`LOST_LOCALISATION`."""
    worst = summary.get("localisation_max")
    return worst is not None and worst > LOST_LOCALISATION


#: A run in which EasyNav's TF listener handled the ``odom → robot`` transforms later than this
#: after their stamps (median, simulated ms; the demo's ``odometry_age``) was overloaded: the
#: machine could not keep up with the simulation, and the stack drove on a TF tree that much in
#: the past. Runs at x2 stayed at 0-25 ms, and 311 of 330 at x4 (on two cores) under 100 ms;
#: the other 19, the heaviest stacks (fusion or GTSAM with the costmap maps manager on the
#: campus, MPPI with OMPL or the simple stack), reached 150 ms to 1.6 s, with nothing between.
#: The worst drew its laser scans with a pose up to 1.4 s old (the latest TF a scan's time
#: had), points metres off the walls on the open campus, and OMPL's paths, kept while clear,
#: were dropped and planned again several times a second (447 m driven for a 195 m tour; at x1
#: the same row drove 196 m with one plan per waypoint); at 220 ms two rows drove 238 m of
#: 195 and 36 m of the sandbox's 15.
OVERLOADED_ODOMETRY_AGE_MS = 100.0


def odometry_lag(summary: dict) -> float | None:
    """The median odometry age (ms) of an overloaded run (above
    :data:`OVERLOADED_ODOMETRY_AGE_MS`); None for a run that kept up or did not measure it."""
    age = (summary.get("odometry_age") or {}).get("median_ms")
    return age if age is not None and age > OVERLOADED_ODOMETRY_AGE_MS else None


def overloaded_fast(summary: dict, speed_up: float) -> bool:
    """Overloaded faster than real time: the run tested the machine, not the combination, and
    runs again at x1. In real time the verdict says so beside the mission's result (once so
    far: OctoMap + OMPL + MPPI in the TurtleBot3 sandbox, 225 ms, 15 ms in another run):
    whether the mission went well is what the row judges."""
    return speed_up > 1.0 and odometry_lag(summary) is not None


@dataclass
class Outcome:
    """What one run of a combination gave (from the demo's summary.json). ``ran``: the code and
    speed it ran with (``11a8747 x2``; the report's "run" column). ``stale``: it ran with params
    other than the combination composes to now (a params file retuned since): to run again.
    ``speed_up``: how much faster than real time it ran. An overloaded run
    (:func:`odometry_lag`) faster than real time tested the machine, not the combination: to
    run again at x1 (``overloaded_fast``); in real time, its verdict says so."""

    combination: Combination
    exit_code: int
    summary: dict = field(default_factory=dict)
    error: str = ""
    ran: str = ""
    stale: bool = False
    speed_up: float = 1.0

    @property
    def overloaded_fast(self) -> bool:
        """Overloaded faster than real time: to run again at x1 (:func:`overloaded_fast`)."""
        return overloaded_fast(self.summary, self.speed_up)

    @property
    def to_run_again(self) -> bool:
        return self.stale or self.overloaded_fast

    @property
    def green(self) -> bool:
        return (self.exit_code == 0 and bool(self.summary.get("success"))
                and not localisation_lost(self.summary))


@dataclass(frozen=True)
class Finding:
    """A failure of the matrix that was looked into: which rows it explains (those using every
    one of ``plugins`` in one of ``worlds``, any world when empty) and what was found. The
    report puts ``cause`` in the verdict of each failed row it explains; a green row ignores it
    (the failure may be intermittent, or fixed since)."""

    plugins: tuple[str, ...]
    worlds: tuple[str, ...]
    cause: str

    def explains(self, combo: Combination) -> bool:
        return set(self.plugins) <= set(combo.plugins) and (
            not self.worlds or combo.world in self.worlds
        )


def load_findings(path: Path = FINDINGS) -> list[Finding]:
    """The findings of ``path`` (a YAML list of ``{plugins, worlds, cause}``); none when the
    file does not exist. Raises ValueError naming the file and the entry that is malformed."""
    if not path.exists():
        return []
    document = yaml.safe_load(path.read_text()) or []
    if not isinstance(document, list):
        raise ValueError(f"{path}: expected a list of findings, got {type(document).__name__}")
    findings = []
    for i, entry in enumerate(document, 1):
        if not isinstance(entry, dict) or set(entry) - {"plugins", "worlds", "cause"}:
            raise ValueError(f"{path}: finding {i}: expected the keys plugins, worlds, cause")
        plugins, worlds, cause = entry.get("plugins"), entry.get("worlds", []), entry.get("cause")
        if (not isinstance(plugins, list) or not plugins
                or not all(isinstance(p, str) for p in plugins)):
            raise ValueError(f"{path}: finding {i}: plugins must be a non-empty list of names")
        if not isinstance(worlds, list) or not all(isinstance(w, str) for w in worlds):
            raise ValueError(f"{path}: finding {i}: worlds must be a list of world names")
        if not isinstance(cause, str) or not cause.strip():
            raise ValueError(f"{path}: finding {i}: cause must say what was found")
        findings.append(Finding(tuple(plugins), tuple(worlds), " ".join(cause.split())))
    return findings


def navigation_plugins() -> dict[str, list[str]]:
    """Installed navigation plugins by axis kind name."""
    kinds = {kind.name: kind for kind in ALL_KINDS}
    found: dict[str, list[str]] = {}
    for _, _, kind_name in AXES:
        found[kind_name] = sorted(
            info.name
            for info in list_plugins(kinds[kind_name])
            if info.distribution not in NOT_NAVIGATION
        )
    return found


@functools.cache
def plugin_class(kind_name: str, name: str) -> type:
    kind = {k.name: k for k in ALL_KINDS}[kind_name]
    return load_plugin_class(kind, name, f"matrix.{kind_name.replace(' ', '_')}")


@functools.cache
def world_sensors(world: str) -> frozenset[str]:
    """The sensors a shipped world's robot has: a laser always; an IMU, a GNSS receiver and a
    3D lidar where the world declares them."""
    from easynav.playground.world_description import WorldDescription

    description = WorldDescription.resolve(world)
    sensors = {"laser"}
    if description.imu is not None:
        sensors.add("imu")
    if description.gnss is not None:
        sensors.add("gnss")
    if description.robot is not None and description.robot.lidar is not None:
        sensors.add("lidar")
    return frozenset(sensors)


def needed_sensors(cls: type) -> set[str]:
    """The sensors a plugin class declares it needs (``NEEDS_SENSORS``)."""
    return set(getattr(cls, "NEEDS_SENSORS", ()))


def combinations(worlds: tuple[str, ...] = WORLDS) -> list[Combination]:
    """Every compatible combination × world, in a stable order."""
    plugins = navigation_plugins()
    classes = {
        (kind, name): plugin_class(kind, name) for kind, names in plugins.items() for name in names
    }
    # Maps stacks: each maps manager that needs no map, alone and with each one that works on
    # what it provides (the routes manager on the costmap).
    stacks: list[tuple[str, ...]] = []
    for base in plugins["maps manager"]:
        base_cls = classes[("maps manager", base)]
        if needed_maps(base_cls):
            continue
        stacks.append((base,))
        for extra in plugins["maps manager"]:
            needs = needed_maps(classes[("maps manager", extra)])
            if needs and compatible(needs, provided_maps(base_cls)):
                stacks.append((base, extra))
    # Pairs of maps managers that need no map, for a plugin that needs maps of both (the NavMap
    # AMCL: the NavMap and the Bonxai voxels). Such a stack only runs the combinations where some
    # plugin needs the pair: the others are the single stacks' again.
    users = [classes[(kind, name)] for kind in ("localizer", "planner", "controller")
             for name in plugins[kind]]

    def provides_of(stack: tuple[str, ...]) -> set[str]:
        return {rep for m in stack for rep in provided_maps(classes[("maps manager", m)])}

    def needs_pair(cls: type, pair: tuple[str, str]) -> bool:
        fits = [compatible(needed_maps(cls), provides_of(s), required_maps(cls))
                for s in (pair, pair[:1], pair[1:])]
        return fits[0] and not fits[1] and not fits[2]

    bases = [m for m in plugins["maps manager"] if not needed_maps(classes[("maps manager", m)])]
    pairs = [pair for pair in itertools.combinations(bases, 2)
             if any(needs_pair(cls, pair) for cls in users)]
    stacks += pairs
    sensors_of = {world: world_sensors(world) for world in worlds}
    combos = []
    for stack, loc, plan, ctrl in itertools.product(
        stacks, plugins["localizer"], plugins["planner"], plugins["controller"]
    ):
        provides = provides_of(stack)
        maps = "+".join(stack)
        chosen = [classes[(kind, name)] for kind, name in
                  (("localizer", loc), ("planner", plan), ("controller", ctrl))]
        if not all(compatible(needed_maps(cls), provides, required_maps(cls)) for cls in chosen):
            continue
        if stack in pairs and not any(needs_pair(cls, stack) for cls in chosen):
            continue
        needs = set().union(*(
            needed_sensors(classes[(kind, name)])
            for kind, name in (("localizer", loc), ("planner", plan), ("controller", ctrl))
        ))
        combos += [
            Combination(maps, loc, plan, ctrl, world)
            for world in worlds
            if needs <= sensors_of[world]
        ]
    return combos


def unmatched_plugins(combos: list[Combination]) -> dict[str, str]:
    """Installed navigation plugins that are in no combination, each with the reason: the
    representation it needs or provides has no partner of some axis (e.g. a maps manager whose
    map no installed localizer can work on)."""
    used = {p for combo in combos for p in combo.plugins}
    plugins = navigation_plugins()
    partners = {
        kind: {rep for name in names for rep in needed_maps(plugin_class(kind, name))}
        for kind, names in plugins.items() if kind != "maps manager"
    }
    reasons = {}
    for kind, names in plugins.items():
        for name in names:
            if name in used:
                continue
            cls = plugin_class(kind, name)
            if kind == "maps manager":
                provides = set(provided_maps(cls))
                missing = [k for k, reps in partners.items()
                           if reps and not provides & reps and k == "localizer"]
                reasons[name] = (
                    f"provides {', '.join(sorted(provides)) or 'nothing'}: no installed "
                    f"{' or '.join(missing) or 'plugin'} works on it"
                )
            elif required_maps(cls):
                reasons[name] = (
                    f"needs {' or '.join(needed_maps(cls))} and {' and '.join(required_maps(cls))}"
                    ": no two installed maps managers provide them, or no partner of another "
                    "axis works beside them"
                )
            elif needed_sensors(cls):
                reasons[name] = (
                    f"needs a {' and '.join(sorted(needed_sensors(cls)))} sensor: none of the "
                    "worlds run has one"
                )
            else:
                reasons[name] = (
                    f"needs {' or '.join(needed_maps(cls))}: its stack lacks a partner of "
                    "another axis (e.g. a localizer for that map)"
                )
    return reasons


def shipped_stacks() -> list[set[str]]:
    """The plugin sets of the shipped params files (params/): stacks known to be tuned."""
    stacks = []
    for _, document in _params_documents():
        plugins = set()
        for node, types_key, _ in AXES:
            params = (document.get(node) or {}).get("ros__parameters") or {}
            for alias in params.get(types_key) or []:
                section = params.get(alias)
                if isinstance(section, dict) and "plugin" in section:
                    plugins.add(section["plugin"])
        if plugins:
            stacks.append(plugins)
    return stacks


def covering_slice(combos: list[Combination]) -> list[Combination]:
    """A few combinations that together use every plugin at least once (greedy set cover).

    Each step takes, among the combinations that use a plugin not yet covered and differ from
    a shipped params file's stack by one plugin at most (a tuned stack with one plugin swapped,
    the way a user swaps one; any combination when none does), the one covering the most new
    plugins, then the one closest to a shipped stack; each in the first of the worlds given
    that suits it. (Closest first, then most new, took 10 combinations where 7 cover the same
    plugins: each a mission of a minute or two in CI.)
    """
    stacks = shipped_stacks()

    def familiarity(plugins: tuple[str, ...]) -> int:
        return max((len(set(plugins) & stack) for stack in stacks), default=0)

    by_plugins: dict[tuple[str, ...], list[Combination]] = {}
    for combo in combos:
        by_plugins.setdefault(combo.plugins, []).append(combo)
    uncovered = {p for combo in combos for p in combo.plugins}
    chosen: list[Combination] = []
    while uncovered:
        candidates = [ps for ps in by_plugins if set(ps) & uncovered]
        one_swap = [ps for ps in candidates if familiarity(ps) >= len(ps) - 1]
        plugins = max(
            one_swap or candidates,
            key=lambda ps: (len(set(ps) & uncovered), familiarity(ps), -len(ps), ps),
        )
        chosen.append(by_plugins[plugins][0])  # the first world given that suits it
        uncovered -= set(plugins)
    return chosen


def ci_slice() -> list[Combination]:
    """The combinations CI runs: the covering slice over every world, so each combination
    drives in the first world that suits it (home, unless it reads a sensor only the campus
    has: the GNSS localizers, the GridMap stack's elevation). CI drives each on
    :func:`slice_waypoints` of its world's tour."""
    return covering_slice(combinations())


#: The world a params file was written for: its "# Run: easynav demo --world NAME" line.
_RUN_WORLD = re.compile(r"^#.*?\bRun:.*?--world\s+(\w+)", re.MULTILINE)


def params_world(text: str) -> str | None:
    """The world a params file's text names in its ``# Run: ... --world NAME`` comment line
    (None: none, the demo's default world)."""
    match = _RUN_WORLD.search(text)
    return match.group(1) if match else None


@functools.lru_cache(maxsize=1)
def _readable_params_files() -> tuple[tuple[Path, str | None, dict], ...]:
    """``(path, world, document)`` of each readable params file, read once (composing the
    thousand combinations reads them for each): the playground's own file, then params/ in
    name order. The documents are shared: a caller copies what it keeps."""
    others = [p for p in sorted(PARAMS_DIR.glob("*.yaml")) if p.resolve() != BASE_PARAMS.resolve()]
    found = []
    for path in [BASE_PARAMS, *others]:
        text = path.read_text()
        try:
            document = load_ros_yaml(text)
        except yaml.YAMLError:
            continue
        if isinstance(document, dict):
            found.append((path, params_world(text), document))
    return tuple(found)


def _params_documents(world: str | None = None):
    """``(path, document)`` of each readable params file: those written for ``world`` (their
    run line names it) first, then the playground's own file (the base of every combination,
    tuned for the indoor worlds), then params/ in name order."""
    files = list(_readable_params_files())
    if world is not None:
        files.sort(key=lambda entry: entry[1] != world)  # stable
    for path, _, document in files:
        yield path, document


def plugin_sections(document: dict):
    """``(alias, section)`` of every navigation plugin a params document configures."""
    for node, types_key, _ in AXES:
        params = (document.get(node) or {}).get("ros__parameters") or {}
        for alias in params.get(types_key) or []:
            section = params.get(alias)
            if isinstance(section, dict) and "plugin" in section:
                yield alias, section


def representative_sections(world: str | None = None) -> dict[str, dict]:
    """For each plugin name, its configuration (alias section) in the first params file that
    uses it: a file written for ``world`` first, then the playground's own file (the base of
    every combination, tuned for the indoor worlds), then the files under params/ in name
    order. (Name order alone once took SimplePlanner from the campus file for every world: 1 m
    of clearance indoors, and the home tour's kitchen goal was refused. The indoor section in
    the campus, 0.2 m, let a robot placed by GNSS alone clip a building's corner.)"""
    sections: dict[str, dict] = {}
    for path, document in _params_documents(world):
        for alias, section in plugin_sections(document):
            sections.setdefault(
                section["plugin"],
                {"file": path.name, "alias": alias, "section": copy.deepcopy(section)},
            )
    return sections


def maps_stack_sections() -> dict[frozenset, dict[str, dict]]:
    """For each stack of two or more maps managers configured together in a params file (the
    NavMap stack's NavMap and Bonxai walls): each one's section in the first file that has
    that stack, files in the order of :func:`representative_sections`. A stack's members are
    tuned for each other: the NavMap AMCL scores on Bonxai walls that its file keeps static
    (``insert_perceptions: false``), where the Bonxai file's own section inserts the sensors'
    points."""
    found: dict[frozenset, dict[str, dict]] = {}
    for _, document in _params_documents():
        params = (document.get("maps_manager_node") or {}).get("ros__parameters") or {}
        members = {}
        for alias in params.get("map_types") or []:
            section = params.get(alias)
            if isinstance(section, dict) and "plugin" in section:
                members[section["plugin"]] = copy.deepcopy(section)
        if len(members) >= 2:
            found.setdefault(frozenset(members), members)
    return found


def compose_params(combo: Combination, sections: dict[str, dict] | None = None) -> dict:
    """The params document of one combination: the playground's file with each axis replaced
    by the chosen plugin's representative section (alias ``matrix``); the heartbeat on, so the
    run reports late RT cycles."""
    sections = representative_sections(combo.world) if sections is None else sections
    document = load_ros_yaml(BASE_PARAMS.read_text())
    chosen = (combo.maps_managers, (combo.localizer,), (combo.planner,), (combo.controller,))
    for (node, types_key, _), plugins in zip(AXES, chosen, strict=True):
        params = document.setdefault(node, {}).setdefault("ros__parameters", {})
        for alias in params.get(types_key) or []:
            params.pop(alias, None)
        aliases = [f"matrix{i or ''}" for i in range(len(plugins))]
        params[types_key] = aliases
        stack = maps_stack_sections().get(frozenset(plugins)) if len(plugins) > 1 else None
        for alias, plugin in zip(aliases, plugins, strict=True):
            known = sections.get(plugin)
            if stack is not None:
                params[alias] = copy.deepcopy(stack[plugin])
                if known and _plans_on(combo.planner, plugin):
                    _take_the_filters(params[alias], known["section"])
            else:
                params[alias] = copy.deepcopy(known["section"]) if known else {"plugin": plugin}
    _add_the_sensors_they_read(document, combo, sections)
    _read_the_robots_sensors(document)
    system = document.setdefault("system_node", {}).setdefault("ros__parameters", {})
    system.setdefault("safety", {}).setdefault("heartbeat", {})["period"] = 0.5
    return document


def _plans_on(planner: str, maps_manager: str) -> bool:
    """Whether ``planner`` works on a map representation that ``maps_manager`` provides."""
    needs = needed_maps(plugin_class("planner", planner))
    return bool(set(needs) & set(provided_maps(plugin_class("maps manager", maps_manager))))


def _take_the_filters(section: dict, own: dict) -> None:
    """A stack member's ``section`` that a row's planner plans on, with the filters of the
    member's own representative ``own`` section where it has none. A stack's file tunes its
    members for the planner it plans with: the NavMap stack's Bonxai walls project to a
    costmap without an inflation filter, as its NavMap planner never reads that costmap. A row
    that plans on that costmap (the CostmapPlanner, which like the original's and Nav2's
    planners keeps off lethal and inflated cells only and knows nothing of the robot's size)
    is configured as the file written for planning on it (Bonxai's own) configures it;
    uninflated, the path ran along walls and the robot hit them (the NavMap stack's
    CostmapPlanner rows on home and the TurtleBot3 sandbox; the rule changes the 24 rows of
    that stack and planner). Where the stack's file is the member's representative one (a row
    in the world the stack's file was written for), the member's section already is its own."""
    if section.get("filters") or not own.get("filters"):
        return
    section["filters"] = list(own["filters"])
    for name in own["filters"]:
        if name in own:
            section[name] = copy.deepcopy(own[name])


#: The kind of robot sensor (:func:`world_sensors`) behind each sensor message type.
SENSOR_KINDS = {
    "sensor_msgs/msg/LaserScan": "laser",
    "sensor_msgs/msg/Imu": "imu",
    "sensor_msgs/msg/NavSatFix": "gnss",
    "sensor_msgs/msg/PointCloud2": "lidar",
}


def _add_the_sensors_they_read(document: dict, combo: Combination, sections: dict) -> None:
    """For each chosen plugin that declares the sensors it needs (``NEEDS_SENSORS``), the
    sensors_node sensors of those kinds (:data:`SENSOR_KINDS`) in its representative params
    file, where the world's robot has them: the fusion and GTSAM localizers read their GNSS fixes
    through sensors_node (group ``gnss``), which the playground's own file (a laser) does not
    declare; without them they never had a fix to start from, and no pose. Another plugin taken
    from the same file (the campus's SimplePlanner) brings none. A sensor the base file already
    declares by name is kept."""
    sensors = document.setdefault("sensors_node", {}).setdefault("ros__parameters", {})
    names = sensors.setdefault("sensors", [])
    robot = world_sensors(combo.world)
    chosen = [("maps manager", m) for m in combo.maps_managers] + [
        ("localizer", combo.localizer), ("planner", combo.planner),
        ("controller", combo.controller),
    ]
    for kind, plugin in chosen:
        known = sections.get(plugin)
        wanted = needed_sensors(plugin_class(kind, plugin)) & robot
        if not known or not wanted:
            continue
        source = next((d for p, _, d in _readable_params_files() if p.name == known["file"]), {})
        theirs = (source.get("sensors_node") or {}).get("ros__parameters") or {}
        for name in theirs.get("sensors") or []:
            sensor = theirs.get(name)
            if (name in names or not isinstance(sensor, dict)
                    or SENSOR_KINDS.get(sensor.get("type")) not in wanted):
                continue
            names.append(name)
            sensors[name] = copy.deepcopy(sensor)


def _read_the_robots_sensors(document: dict) -> None:
    """A maps manager whose section reads a perception group that no sensor of the playground's
    robot is in (the voxel maps' 3D lidar, ``points3d``: no world of the matrix has one) reads
    the ungrouped perceptions instead, the 2D laser, as its user would configure it on a robot
    with a laser only. Left as it is, the stack drives on its static map alone, blind to what
    it passes: on the campus the Bonxai stack cut the cafeteria's corner whenever AMCL's
    along-track error (0.26-0.32 m where no feature across the track is within the laser's
    range) put the robot closer to it than it believed; a stack that marks its laser's hits
    sees the corner where it is."""
    sensors = (document.get("sensors_node") or {}).get("ros__parameters") or {}
    groups = {str((sensors.get(name) or {}).get("group", ""))
              for name in sensors.get("sensors") or []}
    maps = (document.get("maps_manager_node") or {}).get("ros__parameters") or {}
    for alias in maps.get("map_types") or []:
        section = maps.get(alias)
        if isinstance(section, dict) and section.get("perception_group", "") not in groups | {""}:
            section["perception_group"] = ""


#: A mission's wall-clock budget: 6 s per metre of its tour (the start, then each waypoint, in
#: straight lines), 600 s (the demo's default) at least. The slowest green tours so far took
#: 2.8 (campus) to 14.6 (SeReST between tb3_sandbox's pillars) simulated s per metre, the short
#: tours well inside 600 s; the campus's 180 m, at the 0.8 real-time factor of two missions
#: on two cores, passed 600 s with four of five waypoints reached.
TIMEOUT_PER_METRE = 6.0
MIN_TIMEOUT = 600.0


#: CI's slice drives the legs of each world's tour that fit in this far (the start, then each
#: waypoint, in straight lines; the first leg at least): home's whole tour (15 m) and the
#: campus's first leg (30 m), where the whole campus tour (180 m) takes 4 to 8 minutes a row.
SLICE_TOUR_METRES = 40.0


@functools.cache
def tour_legs(world: str) -> tuple[float, ...]:
    """The lengths of the legs of ``world``'s tour: the start to its first waypoint, then each
    waypoint to the next, in straight lines (m)."""
    from easynav.playground.world_description import WorldDescription, load_waypoints

    description = WorldDescription.resolve(world)
    waypoints = load_waypoints(description.waypoints_path)
    points = [description.start_pose[:2]] + [w[:2] for w in waypoints]
    return tuple(math.dist(a, b) for a, b in zip(points, points[1:], strict=False))


def slice_waypoints(world: str, metres: float = SLICE_TOUR_METRES) -> int | None:
    """How many of ``world``'s waypoints CI's slice drives to: as many as fit in ``metres`` of
    tour, one at least; None when the whole tour fits."""
    legs = tour_legs(world)
    count = max(1, sum(1 for total in itertools.accumulate(legs) if total <= metres))
    return None if count >= len(legs) else count


def mission_timeout(world: str, waypoints: int | None = None) -> float:
    """Wall seconds before a mission in ``world`` (its first ``waypoints``, None: all) is
    cancelled (see TIMEOUT_PER_METRE)."""
    tour = sum(tour_legs(world)[:waypoints])
    return max(MIN_TIMEOUT, TIMEOUT_PER_METRE * tour)


class _Tee(io.TextIOBase):
    """``sys.stderr`` that also copies what Python code writes to ``copy``. Code that needs a
    file descriptor (a StringIO has none: the demo failed with "fileno") gets the real one."""

    def __init__(self, stream, copy: io.StringIO) -> None:
        self._stream, self._copy = stream, copy

    def write(self, text: str) -> int:
        self._copy.write(text)
        return self._stream.write(text)

    def flush(self) -> None:
        self._stream.flush()

    def fileno(self) -> int:
        return self._stream.fileno()


def run_combination(
    combo: Combination, run_dir: Path, speed_up: float = 1.0, timeout: float | None = None,
    waypoints: int | None = None,
) -> Outcome:
    """Run one combination's waypoint mission in the playground (``timeout``: wall seconds,
    by default :func:`mission_timeout` of its world; ``waypoints``: only the first ones of the
    world's tour, None: all)."""
    from easynav.playground.demo import run_demo
    from easynav.playground.world_description import (
        WorldDescription,
        load_waypoint_levels,
        load_waypoints,
    )

    run_dir.mkdir(parents=True, exist_ok=True)
    params = run_dir / "matrix.params.yaml"
    params.write_text(yaml.safe_dump(compose_params(combo), sort_keys=False))
    out = io.StringIO()
    try:
        tour = None
        if waypoints is not None:
            path = WorldDescription.resolve(combo.world).waypoints_path
            if load_waypoint_levels(path):  # a list has no floors: a tour of floors runs whole
                raise ValueError(f"{combo.world}'s tour has floors: it cannot be cut short")
            tour = load_waypoints(path)[:waypoints]
        # run_demo prints a usage error (a bad world, a params file it cannot read) to stderr:
        # a copy goes to ``out``, so that the row says it instead of "exit 2".
        with contextlib.redirect_stderr(_Tee(sys.stderr, out)):
            code = run_demo(
                world=combo.world,
                params_file=params,
                waypoints=tour,
                speed_up=speed_up,
                output_png=run_dir / "run.png",
                timeout=mission_timeout(combo.world, waypoints) if timeout is None else timeout,
                run_dir=run_dir / "run",
                stream=out,
            )
    except Exception as exc:  # a crash of the harness is a row, not the end of the matrix
        return Outcome(combo, 1, error=f"{type(exc).__name__}: {exc}")
    finally:  # the demo's progress lines and summary, to look into a run afterwards
        (run_dir / "demo.log").write_text(out.getvalue())
    summary_path = run_dir / "run" / "summary.json"
    summary = json.loads(summary_path.read_text()) if summary_path.exists() else {}
    error = ""
    if code != 0:
        lines = [line for line in out.getvalue().splitlines() if line.strip()]
        error = summary.get("status_message") or (lines[-1] if lines else f"exit {code}")
    return Outcome(combo, code, summary, error)


def _first_line(text: str) -> str:
    """The first non-blank line of ``text`` (a multi-line error in one table cell)."""
    return next((line.strip() for line in str(text).splitlines() if line.strip()), "")


def _num(value, fmt: str) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    return format(value, fmt)


def failure(outcome: Outcome) -> str:
    """What a user would notice first: collisions, goals missed, a lost localisation, then the
    run's own message (which can be the navigation's result, "Navigation successfully
    finished", when the mission failed on a collision)."""
    s = outcome.summary
    found = []
    if s.get("collisions"):
        found.append(f"{s['collisions']} collision(s)")
    if s.get("waypoints") and s.get("reached", 0) < s["waypoints"]:
        found.append(f"{s.get('reached', 0)} of {s['waypoints']} waypoints reached")
    if localisation_lost(s):
        found.append(f"localisation lost: {s['localisation_max']:.1f} m off at worst (mean "
                     f"{_num(s.get('localisation_mean'), '.1f')} m, more than "
                     f"{LOST_LOCALISATION:g} m fails a row)")
    if odometry_lag(s) is not None:
        found.append(_overloaded(s))
    if outcome.error:
        found.append(_first_line(outcome.error))
    return "; ".join(found) or "see the run"


def _overloaded(summary: dict) -> str:
    return (f"overloaded: EasyNav's TF listener handled odom → robot "
            f"{odometry_lag(summary):.0f} ms after its stamp (median, simulated; more than "
            f"{OVERLOADED_ODOMETRY_AGE_MS:g} ms)")


def verdict(outcome: Outcome, findings: list[Finding] = ()) -> str:
    """A row's verdict: green, or what failed and why (the findings that explain it), or that
    nobody has looked into it yet; a stale row (run with params since changed) says so, and
    an overloaded one (:func:`odometry_lag`): to run again at x1 when it ran faster."""
    stale = " (**stale**: run with params changed since; to run again)" if outcome.stale else ""
    if outcome.overloaded_fast:
        return (f"**overloaded** at x{outcome.speed_up:g}{stale}: EasyNav's TF listener handled "
                f"odom → robot {odometry_lag(outcome.summary):.0f} ms after its stamp (median, "
                "simulated), the run tested the machine, not the combination; to run again at x1")
    if outcome.green:
        lag = odometry_lag(outcome.summary) is not None
        return "green" + (f", but {_overloaded(outcome.summary)}" if lag else "") + stale
    causes = [f.cause for f in findings if f.explains(outcome.combination)]
    if causes:
        return f"**FAILED**{stale}: {failure(outcome)}. Why: {' '.join(causes)}"
    return f"**FAILED** (not looked into yet){stale}: {failure(outcome)}"


def markdown(outcomes: list[Outcome], header: str, unmatched: dict[str, str] | None = None,
             findings: list[Finding] = ()) -> str:
    """docs/matrix.md: one row per run, then the plugins that are in no combination."""
    lines = [
        header,
        "",
        "| maps manager | localizer | planner | controller | world | reached | "
        "time (s, simulated) | distance (m) | min clearance (m) | loc. error mean / max (m) | "
        "late RT cycles | run | verdict |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for o in outcomes:
        s, c = o.summary, o.combination
        lines.append(
            f"| `{c.maps_manager}` | `{c.localizer}` | `{c.planner}` | `{c.controller}` | "
            f"{c.world} | {s.get('reached', 0)}/{s.get('waypoints', '?')} | "
            f"{_num(s.get('navigation_time'), '.1f')} | {_num(s.get('distance_driven'), '.1f')} | "
            f"{_num(s.get('min_clearance'), '.2f')} | "
            f"{_num(s.get('localisation_mean'), '.3f')} / {_num(s.get('localisation_max'), '.3f')}"
            f" | {_num(s.get('late_rt_cycles'), 'd')} | {o.ran or '—'} | "
            f"{verdict(o, findings).replace('|', '/')} |"
        )
    current = [o for o in outcomes if not o.to_run_again]
    green = sum(o.green for o in current)
    explained = sum(not o.green and any(f.explains(o.combination) for f in findings)
                    for o in current)
    stale = sum(o.stale for o in outcomes)
    overloaded = sum(o.overloaded_fast and not o.stale for o in outcomes)
    lines += ["", f"{green} of {len(current)} runs green; of the {len(current) - green} "
              f"failed, {explained} explained (tests/matrix/findings.yaml)"
              + (f"; and {stale} stale runs (run with params changed since: to run again)"
                 if stale else "")
              + (f"; and {overloaded} overloaded runs (faster than real time: to run again at "
                 "x1)" if overloaded else "") + ".", ""]
    if unmatched:
        lines += ["Installed navigation plugins in no combination (nothing to run them with):", ""]
        lines += [f"- `{name}`: {reason}" for name, reason in sorted(unmatched.items())]
        lines.append("")
    return "\n".join(lines)
