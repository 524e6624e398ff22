"""Deriving the demo's params file: the map and start pose of the world being run."""

from __future__ import annotations

from pathlib import Path

import yaml

from easynav.controllers.serest_tracker import SEREST_DEFAULTS
from easynav.system.cli.params_file import load_ros_yaml

SIMPLE_MAPS_MANAGER = "easynav_simple_maps_manager/SimpleMapsManager"
#: Maps managers that load a ROS map-server YAML through ``package`` / ``map_path_file``.
MAP_SERVER_MAPS_MANAGERS = ("easynav_costmap_maps_manager/CostmapMapsManager",)
#: Maps managers of elevation maps (a gridmap file through ``package`` / ``map_path_file``).
GRIDMAP_MAPS_MANAGERS = ("easynav_gridmap_maps_manager/GridmapMapsManager",)
#: Voxel maps managers that extrude a map-server YAML given as ``occmap_path_file``, and the
#: parameter naming their own map file (emptied, so that the world's map is the one loaded).
VOXEL_MAPS_MANAGERS = {
    "easynav_octomap_maps_manager/OctomapMapsManager": "octomap_path_file",
    "easynav_bonxai_maps_manager/BonxaiMapsManager": "bonxai_path_file",
}
#: Localizers scored from the Odometry topic (map frame) they publish rather than from TF: the
#: original's GpsLocalizer broadcast an identity ``map -> odom`` (TF scored the odometry); ours
#: follows its estimate, and its topic is the estimate itself (with the IMU filter's heading).
ESTIMATE_TOPICS = {"easynav_gps_localizer/GpsLocalizer": "/robot/odom_gps"}


def _get(section: dict, dotted: str, default=None):
    """A parameter of a node section, nested (``a: {b: 1}``) or flat (``a.b: 1``)."""
    if dotted in section:
        return section[dotted]
    node = section
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return default
        node = node[part]
    return node


def _set(section: dict, dotted: str, value) -> None:
    """Set a parameter where it is written (flat key if present), nested otherwise."""
    if dotted in section:
        section[dotted] = value
        return
    parts = dotted.split(".")
    node = section
    for part in parts[:-1]:
        node = node.setdefault(part, {})
    node[parts[-1]] = value


def _ros_parameters(params: dict, node: str) -> dict | None:
    section = params.get(node)
    if not isinstance(section, dict):
        return None
    return section.get("ros__parameters")


SEREST_CONTROLLER = "easynav_serest_controller/SerestController"
#: SeReST's default d0_margin (the original's), for an alias that does not set it.
SEREST_D0_DEFAULT = SEREST_DEFAULTS["d0_margin"]
#: The least room SeReST keeps between the robot's body and an obstacle in the demo (m).
SEREST_BODY_MARGIN = 0.05


def _serest_margin_for_robot(params: dict, robot_radius: float) -> list[str]:
    """Raise every SerestController alias's ``d0_margin`` to ``robot_radius`` +
    :data:`SEREST_BODY_MARGIN` where smaller; the notes."""
    controllers = _ros_parameters(params, "controller_node") or {}
    floor = round(robot_radius + SEREST_BODY_MARGIN, 6)
    notes = []
    for alias in controllers.get("controller_types", []) or []:
        if _get(controllers, f"{alias}.plugin") != SEREST_CONTROLLER:
            continue
        d0 = float(_get(controllers, f"{alias}.d0_margin", SEREST_D0_DEFAULT))
        if d0 < floor:
            _set(controllers, f"{alias}.d0_margin", floor)
            notes.append(
                f"controller_node.{alias}.d0_margin {d0:g} -> {floor:g}: the world's robot is "
                f"{robot_radius:g} m (the margin is from its centre)"
            )
    return notes


def derive_params(
    params_path: Path,
    map_file: Path,
    start_pose: tuple[float, float, float],
    out_path: Path,
    map_yaml: Path | None = None,
    robot_radius: float | None = None,
    robot_height: float | None = None,
    elevation_file: Path | None = None,
) -> tuple[list[str], str | None]:
    """Write ``out_path``: the params file with the world's map and start pose, sim time on.

    - every ``SimpleMapsManager`` alias loads ``map_file`` (a ``.map``; ``package`` emptied);
    - every ``CostmapMapsManager`` alias loads ``map_yaml`` (the world's map-server YAML;
      ``package`` emptied) when given;
    - every ``OctomapMapsManager`` / ``BonxaiMapsManager`` alias extrudes ``map_yaml``
      (``occmap_path_file``; its own map file and ``package`` emptied) when given;
    - every ``GridmapMapsManager`` alias loads ``elevation_file`` (the world's elevation map:
      :meth:`WorldDescription.elevation_map`; ``package`` emptied) when given;
    - every localizer alias with an ``initial_pose`` starts at ``start_pose``;
    - ``system_node.robot_geometry.radius`` is ``robot_radius`` and ``.height`` is
      ``robot_height`` when given (the world's robot);
    - every ``SerestController`` alias keeps ``d0_margin`` (measured from the robot's centre)
      at least ``robot_radius`` + :data:`SEREST_BODY_MARGIN`: a file written for a smaller
      robot would let a larger one's body reach the obstacle before SeReST stops;
    - ``use_sim_time: true`` on every node (the playground's /clock is the time).

    Returns the notes of what was changed and the planner's debug path topic (None without a
    planner).

    Raises:
        FileNotFoundError: no params file.
        ValueError: not an EasyNav params file (no ``<node>: ros__parameters:`` section).
    """
    params = load_ros_yaml(Path(params_path).read_text())
    if not isinstance(params, dict) or not any(
        isinstance(v, dict) and "ros__parameters" in v for v in params.values()
    ):
        raise ValueError(f"{params_path}: not a ROS params file (no '<node>: ros__parameters:')")
    notes = []
    if robot_radius is not None:
        system = params.setdefault("system_node", {}).setdefault("ros__parameters", {})
        if _get(system, "robot_geometry.radius") != robot_radius:
            _set(system, "robot_geometry.radius", float(robot_radius))
            notes.append(f"system_node.robot_geometry.radius = {robot_radius:g}, the world's robot")
        # The playground's robots are discs: an inscribed radius set for a smaller robot would
        # let the inflation filters' cost 253 stop short of the world's robot.
        inscribed = _get(system, "robot_geometry.inscribed_radius")
        if inscribed is not None and float(inscribed) < robot_radius:
            _set(system, "robot_geometry.inscribed_radius", float(robot_radius))
            notes.append(f"system_node.robot_geometry.inscribed_radius {float(inscribed):g} -> "
                         f"{robot_radius:g}, the world's robot (a disc)")
    if robot_radius is not None:
        notes.extend(_serest_margin_for_robot(params, float(robot_radius)))
    if robot_height is not None:
        system = params.setdefault("system_node", {}).setdefault("ros__parameters", {})
        if _get(system, "robot_geometry.height") != robot_height:
            _set(system, "robot_geometry.height", float(robot_height))
            notes.append(f"system_node.robot_geometry.height = {robot_height:g}, the world's robot")

    for node, section in params.items():
        if isinstance(section, dict) and isinstance(section.get("ros__parameters"), dict):
            if section["ros__parameters"].get("use_sim_time") is not True:
                notes.append(f"{node}.use_sim_time set to true (the playground's /clock)")
            section["ros__parameters"]["use_sim_time"] = True

    maps = _ros_parameters(params, "maps_manager_node") or {}
    for alias in maps.get("map_types", []) or []:
        plugin = _get(maps, f"{alias}.plugin")
        if plugin == SIMPLE_MAPS_MANAGER:
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.map_path_file", str(map_file))
            notes.append(f"maps_manager_node.{alias} loads the world's map {map_file}")
        elif plugin in VOXEL_MAPS_MANAGERS and map_yaml is not None:
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.{VOXEL_MAPS_MANAGERS[plugin]}", "")
            _set(maps, f"{alias}.occmap_path_file", str(map_yaml))
            notes.append(f"maps_manager_node.{alias} extrudes the world's map {map_yaml}")
        elif plugin in GRIDMAP_MAPS_MANAGERS and elevation_file is not None:
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.map_path_file", str(elevation_file))
            notes.append(
                f"maps_manager_node.{alias} loads the world's elevation map {elevation_file}"
            )
        elif plugin in MAP_SERVER_MAPS_MANAGERS and map_yaml is not None:
            _set(maps, f"{alias}.package", "")
            _set(maps, f"{alias}.map_path_file", str(map_yaml))
            notes.append(f"maps_manager_node.{alias} loads the world's map {map_yaml}")
        else:
            notes.append(
                f"maps_manager_node.{alias} ({_get(maps, f'{alias}.plugin')}) keeps the map of "
                "the params file: make sure it is the world's"
            )

    localizer = _ros_parameters(params, "localizer_node") or {}
    x, y, yaw = start_pose
    for alias in localizer.get("localizer_types", []) or []:
        if _get(localizer, f"{alias}.initial_pose") is not None:
            for key, value in (("x", x), ("y", y), ("yaw", yaw)):
                _set(localizer, f"{alias}.initial_pose.{key}", float(value))
            notes.append(
                f"localizer_node.{alias}.initial_pose = ({x:.2f}, {y:.2f}, {yaw:.2f}), the start"
            )

    planner = _ros_parameters(params, "planner_node") or {}
    planner_types = planner.get("planner_types", []) or []
    path_topic = f"/planner_node/{planner_types[0]}/path" if planner_types else None
    Path(out_path).write_text(yaml.safe_dump(params, sort_keys=False))
    return notes, path_topic


LASER_SCAN = "sensor_msgs/msg/LaserScan"


def laser_scan_topics(params_path: Path) -> list[str]:
    """The topics sensors_node reads a ``sensor_msgs/msg/LaserScan`` from, in the order of its
    ``sensors`` list (the playground's laser must publish there: the original's Kobuki
    playground uses ``/scan_raw``, this playground ``scan``).

    Raises:
        FileNotFoundError: no params file.
    """
    params = yaml.safe_load(Path(params_path).read_text())
    sensors = _ros_parameters(params, "sensors_node") if isinstance(params, dict) else None
    topics = []
    for name in (sensors or {}).get("sensors", []) or []:
        if _get(sensors, f"{name}.type") == LASER_SCAN:
            topic = _get(sensors, f"{name}.topic")
            if topic:
                topics.append(str(topic))
    return topics


def planner_plugins(params_path: Path) -> list[str]:
    """The plugin strings of the planner aliases of a params file (empty when none or when the
    file cannot be read: the demo only uses them to choose its reachability warning)."""
    try:
        params = yaml.safe_load(Path(params_path).read_text())
    except (OSError, yaml.YAMLError):
        return []
    if not isinstance(params, dict):
        return []
    planner = _ros_parameters(params, "planner_node") or {}
    return [str(_get(planner, f"{a}.plugin", "")) for a in planner.get("planner_types", []) or []]


def pose_estimate_topic(params_path: Path) -> str | None:
    """Where the localizer of a params file publishes its estimate when TF does not carry it
    (:data:`ESTIMATE_TOPICS`); None when TF does, or when the file cannot be read."""
    try:
        params = yaml.safe_load(Path(params_path).read_text())
    except (OSError, yaml.YAMLError):
        return None
    localizer = (_ros_parameters(params, "localizer_node") if isinstance(params, dict) else None)
    for alias in (localizer or {}).get("localizer_types", []) or []:
        topic = ESTIMATE_TOPICS.get(str(_get(localizer, f"{alias}.plugin", "")))
        if topic:
            return topic
    return None


def derive_fleet_params(
    params_path: Path,
    map_file: Path,
    robots: list[tuple[str, tuple[float, float, float]]],
    out_path: Path,
    **kwargs,
) -> tuple[list[str], dict[str, str | None]]:
    """Write ``out_path``: one params file for several robots, the original's multi-robot
    layout (``r1/controller_node: ros__parameters: ...``, one section per robot and node).

    Each robot ``(name, start_pose)`` gets the sections :func:`derive_params` derives for it
    (``kwargs`` are its options), under ``<name>/<node>``, with ``system_node.tf_prefix`` set to
    its name (frames ``r1/map``, ``r1/odom``, ``r1/base_footprint``...) and every sensor topic
    made relative (``/scan`` becomes ``scan``: ``/r1/scan`` in namespace ``r1``). Run each with
    ``easynav run OUT --namespace NAME`` (or ``--ros-args -r __ns:=/NAME``).

    Returns the notes and each robot's planner path topic (``/r1/planner_node/<alias>/path``;
    None without a planner).

    Raises:
        FileNotFoundError: no params file.
        ValueError: not an EasyNav params file, or one with namespaced sections already.
    """
    document: dict = {}
    notes: list[str] = []
    path_topics: dict[str, str | None] = {}
    for name, start_pose in robots:
        part = Path(out_path).with_name(f"{Path(out_path).stem}.{name}.part.yaml")
        robot_notes, path_topic = derive_params(params_path, map_file, start_pose, part, **kwargs)
        params = yaml.safe_load(part.read_text())
        part.unlink()
        if not notes:
            notes += robot_notes
        for node, section in params.items():
            if "/" in str(node) or "*" in str(node):
                raise ValueError(
                    f"{params_path}: section {node!r} is namespaced already; give a "
                    "single-robot file (the robots' sections are derived from it)"
                )
            document[f"{name}/{node}"] = section
        system = document.setdefault(f"{name}/system_node", {}).setdefault(
            "ros__parameters", {}
        )
        system["tf_prefix"] = name
        sensors = _ros_parameters(document, f"{name}/sensors_node") or {}
        for sensor in sensors.get("sensors", []) or []:
            topic = _get(sensors, f"{sensor}.topic")
            if isinstance(topic, str) and topic.startswith("/"):
                _set(sensors, f"{sensor}.topic", topic.lstrip("/"))
        path_topics[name] = f"/{name}{path_topic}" if path_topic else None
    names = [name for name, _ in robots]
    notes.append(
        f"one section per robot and node ({', '.join(f'{n}/...' for n in names)}), "
        "system_node.tf_prefix = the robot's name, sensor topics relative to its namespace"
    )
    Path(out_path).write_text(yaml.safe_dump(document, sort_keys=False))
    return notes, path_topics
