"""WorldDescription: a world with its start pose, moving obstacles and default waypoints."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np
import yaml

from easynav.playground.robot_description import RobotDescription
from easynav.playground.sim.box_obstacle import BoxObstacle
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.multilevel import MultiLevelWorld
from easynav.playground.sim.scripted_obstacle import ScriptedObstacle
from easynav.playground.sim.terrain import Terrain
from easynav.playground.sim.world import World

WORLDS_DIR = Path(str(resources.files("easynav.playground") / "worlds"))
#: Keys of a moving-obstacle entry that make it a :class:`ScriptedObstacle`.
_SCRIPT_KEYS = {"start_time", "start_distance", "repeat", "pause"}
#: Height (m) of a flat world's occupied cells in its elevation map (walls, buildings): the
#: slope beside one is far above any a robot drives, so the GridMap planners keep off them.
WALL_ELEVATION = 2.0
#: Keys of a world's ``imu`` and ``gnss`` sections (playground parameters ``imu.*``, ``gnss.*``).
_IMU_KEYS = {"rate", "gyro_noise", "gyro_bias", "accel_noise", "yaw_noise"}
_GNSS_KEYS = {"rate", "noise", "jump_probability", "jump_distance", "outages"}


@dataclass(frozen=True)
class RobotEntry:
    """One robot of a multi-robot world: its ``name`` (namespace and tf_prefix), start pose
    and waypoint file (None: none)."""

    name: str
    start_pose: tuple[float, float, float]
    waypoints_path: Path | None = None


@dataclass
class WorldDescription:
    """Everything the playground needs to set up a run.

    A description file (``worlds/home.yaml``) reads::

        map: home.map                  # .map or map-server .yaml, relative to this file
        start_pose: [5.6, 3.4, 0.0]    # x, y, yaw of the robot in the map frame
        waypoints: home.waypoints.yaml # default waypoint list of the demo (optional)
        moving_obstacles:              # optional
          - {name: person, radius: 0.2, speed: 0.3, waypoints: [[5.0, 0.9], [6.2, 0.9]]}
          # scripted (any of start_time, start_distance, repeat, pause): waits at its first
          # waypoint until start_time (s) and, if given, until the robot is within
          # start_distance (m) of it, then walks the waypoints once (repeat: false, the
          # default; standing pause s at each intermediate waypoint) or back and forth
          - {name: crosser, speed: 0.5, start_distance: 1.3, pause: 4.0,
             waypoints: [[7.1, 4.3], [7.1, 3.4], [7.1, 5.6]]}
        robot:                         # optional: the robot of this world (RobotDescription)
          radius: 0.15
          limits: {max_linear_vel: 0.3}
          laser: {max_range: 3.5}
        geodetic_origin: [40.28, -3.82, 746.0]  # optional: lat, lon, alt of the map origin
        imu: {rate: 50.0, gyro_bias: 0.002}     # optional: the robot has an IMU (imu.* params)
        gnss: {rate: 5.0, noise: 0.2, outages: [[60, 75]]}  # optional: a GNSS receiver
                                                # (gnss.* params; needs geodetic_origin)
        furniture:                     # optional: boxes with a height range (BoxObstacle)
          - {name: low shelf, box: [7.5, 3.0, 8.5, 3.4], z: [0.3, 0.4]}
        terrain:                       # optional: ground heights (flat without the key)
          elevation: maps/uneven_terrain.yaml  # a gridmap file (GridmapMapsManager's formats)
          max_climb_slope_deg: 30.0    # the robot cannot climb steeper ground (Terrain)
        levels: {floors: [...], ramps: [...], solids: [...], ...}  # optional: a multi-level
                                       # world (MultiLevelWorld; `map` is then a 2D map of its
                                       # ground floor for the tools, not the simulation's walls)
        robots:                        # optional: several robots (`--robots N` takes the first
          - name: r1                   # N); each its namespace, tf_prefix, start and waypoints
            start_pose: [1.0, 1.0, 0.0]
            waypoints: crossing.r1.waypoints.yaml
          - {name: r2, start_pose: [5.0, 1.0, 3.14], waypoints: crossing.r2.waypoints.yaml}

    Thread contract: plain data; build it before starting threads.
    """

    world: World
    map_path: Path | None = None
    start_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)
    obstacles: list[dict] = field(default_factory=list)
    waypoints_path: Path | None = None
    source: str = ""
    robot: RobotDescription = field(default_factory=RobotDescription)
    geodetic_origin: tuple[float, float, float] | None = None
    imu: dict | None = None
    gnss: dict | None = None
    furniture: list[BoxObstacle] = field(default_factory=list)
    terrain_path: Path | None = None
    max_climb_slope_deg: float = 30.0
    robots: list[RobotEntry] = field(default_factory=list)
    levels: dict | None = None

    def make_levels(self, robot_height: float | None = None,
                    laser_height: float = 0.25) -> MultiLevelWorld | None:
        """The world's :class:`MultiLevelWorld` (its ``levels`` section) for a robot of
        ``robot_height`` (default: the world's robot) with its laser at ``laser_height``; None
        for a world without levels."""
        if self.levels is None:
            return None
        height = robot_height if robot_height is not None else (self.robot.height or 0.5)
        return MultiLevelWorld.from_dict(self.levels, f"{self.source}: levels", float(height),
                                         float(laser_height), name=self.world.name)

    def fleet(self, count: int) -> list[RobotEntry]:
        """The first ``count`` robots of :attr:`robots` (a multi-robot run).

        Raises:
            ValueError: ``count`` < 2, or more robots than the world declares (names both).
        """
        if count < 2:
            raise ValueError(f"a fleet has at least 2 robots, got {count}")
        if len(self.robots) < count:
            raise ValueError(
                f"world '{self.world.name}' ({self.source or 'built in'}) declares "
                f"{len(self.robots)} robot(s) in 'robots', {count} asked for"
            )
        return self.robots[:count]

    def make_terrain(self) -> Terrain | None:
        """The world's :class:`Terrain` (heights from :attr:`terrain_path`, the climb limit),
        None for a flat world."""
        if self.terrain_path is None:
            return None
        return Terrain.load(self.terrain_path, self.max_climb_slope_deg)

    def elevation_map(self, directory: Path) -> Path | None:
        """The world's elevation map as a gridmap file (what GridmapMapsManager loads), absolute;
        None for a world of several levels (one height per cell cannot hold two floors).

        A world with terrain: its heights file as it is (the occupied cells of its map, such as
        the ``uneven`` world's fence, are not added). A flat world: the ground at 0 m with its
        occupied cells raised :data:`WALL_ELEVATION` (what an elevation mapping of the world
        would hold), on the map's own grid, written into ``directory`` as
        ``world_elevation.npz``. Without it the GridMap stack would have no map of the world.
        """
        if self.levels is not None:
            return None
        if self.terrain_path is not None:
            return self.terrain_path.resolve()
        from easynav.maps.gridmap import GridMap, save_gridmap_npz

        world = self.world
        elevation = np.where(world.occupied, WALL_ELEVATION, 0.0)
        grid = GridMap(world.resolution, world.origin_x, world.origin_y, {"elevation": elevation})
        return save_gridmap_npz(grid, Path(directory) / "world_elevation.npz").resolve()

    def sensor_parameter_defaults(self) -> dict[str, object]:
        """Playground parameter defaults of this world's IMU and GNSS (``imu.enabled``,
        ``imu.rate``, ``gnss.noise``, ``gnss.outages`` flattened to ``[s0, e0, s1, e1...]``)."""
        values: dict[str, object] = {}
        for name, spec in (("imu", self.imu), ("gnss", self.gnss)):
            if spec is None:
                continue
            values[f"{name}.enabled"] = True
            for key, value in spec.items():
                if key == "outages":
                    value = [float(v) for window in value for v in window]
                values[f"{name}.{key}"] = value
        if self.geodetic_origin is not None:
            values["geodetic_origin"] = list(self.geodetic_origin)
        return values

    def map_server_yaml(self, directory: Path) -> Path:
        """The world's map as a map-server YAML (what the costmap and voxel maps managers
        load): its own file when it is one (unknown cells stay unknown), else a conversion
        written into ``directory``. Absolute."""
        path = self.map_path
        if path is None or path.suffix.lower() not in (".yaml", ".yml"):
            path = self.world.save_map_server_yaml(Path(directory) / "world.yaml")
        return path.resolve()

    def make_obstacles(self) -> list[MovingObstacle]:
        """Fresh :class:`MovingObstacle` objects (at their first waypoint); a
        :class:`ScriptedObstacle` for an entry with ``start_time``, ``start_distance``,
        ``repeat`` or ``pause``.

        Raises:
            ValueError: a malformed obstacle entry (names the entry).
        """
        result = []
        for i, spec in enumerate(self.obstacles):
            if not isinstance(spec, dict) or "waypoints" not in spec:
                raise ValueError(f"{self.source}: moving_obstacles[{i}] needs 'waypoints'")
            unknown = set(spec) - {"name", "radius", "speed", "waypoints", *_SCRIPT_KEYS}
            if unknown:
                raise ValueError(f"{self.source}: moving_obstacles[{i}] has unknown keys {unknown}")
            common = {
                "radius": float(spec.get("radius", 0.25)),
                "speed": float(spec.get("speed", 0.4)),
                "name": str(spec.get("name", f"obstacle {i}")),
            }
            if not _SCRIPT_KEYS & set(spec):
                result.append(MovingObstacle(spec["waypoints"], **common))
                continue
            repeat = spec.get("repeat", False)
            if not isinstance(repeat, bool):
                raise ValueError(
                    f"{self.source}: moving_obstacles[{i}].repeat must be true or false, "
                    f"got {repeat!r}"
                )
            distance = spec.get("start_distance")
            result.append(
                ScriptedObstacle(
                    spec["waypoints"],
                    **common,
                    start_time=float(spec.get("start_time", 0.0)),
                    start_distance=None if distance is None else float(distance),
                    repeat=repeat,
                    pause=float(spec.get("pause", 0.0)),
                )
            )
        return result

    @classmethod
    def resolve(cls, spec: str) -> WorldDescription:
        """Find a world from a name or a path.

        ``spec`` may be the name of a shipped world (``home``, ``office``), a world description
        YAML (has a ``map`` key), a map-server YAML (has an ``image`` key) or a ``.map`` file.
        Plain maps start the robot at ``(0, 0, 0)`` with no obstacles.

        Raises:
            FileNotFoundError: neither a shipped world nor an existing file (lists the names).
            ValueError: a malformed file.
        """
        shipped = WORLDS_DIR / f"{spec}.yaml"
        if "/" not in spec and not spec.endswith((".yaml", ".yml", ".map")) and shipped.exists():
            return cls.from_description_file(shipped)
        path = Path(spec)
        if not path.exists():
            names = sorted(p.stem for p in WORLDS_DIR.glob("*.yaml") if ".waypoints" not in p.name)
            raise FileNotFoundError(
                f"world {spec!r}: no such file and not a shipped world (shipped: {names})"
            )
        if path.suffix.lower() == ".map":
            return cls(World.from_map_file(path), map_path=path, source=str(path))
        data = yaml.safe_load(path.read_text())
        if isinstance(data, dict) and "map" in data:
            return cls.from_description_file(path)
        if isinstance(data, dict) and "image" in data:
            return cls(World.from_ros_map_yaml(path), map_path=path, source=str(path))
        raise ValueError(
            f"{path}: neither a world description (key 'map') nor a map-server YAML (key 'image')"
        )

    @classmethod
    def from_description_file(cls, path: str | Path) -> WorldDescription:
        """Load a world description YAML (see the class documentation).

        Raises:
            ValueError: a missing ``map`` key, a malformed ``start_pose`` or ``robot``, or
                unknown keys.
        """
        path = Path(path)
        data = yaml.safe_load(path.read_text())
        if not isinstance(data, dict) or "map" not in data:
            raise ValueError(f"{path}: a world description needs a 'map' key")
        unknown = set(data) - {
            "map", "start_pose", "waypoints", "moving_obstacles", "robot", "furniture",
            "geodetic_origin", "imu", "gnss", "terrain", "robots", "levels",
        }
        if unknown:
            raise ValueError(f"{path}: unknown keys {sorted(unknown)}")
        map_path = path.parent / data["map"]
        world = World.load(map_path)
        start = data.get("start_pose", [0.0, 0.0, 0.0])
        if not (isinstance(start, list) and len(start) == 3):
            raise ValueError(f"{path}: start_pose must be [x, y, yaw], got {start!r}")
        start_pose = tuple(float(v) for v in start)
        if not all(math.isfinite(v) for v in start_pose):
            raise ValueError(f"{path}: start_pose must be finite, got {start!r}")
        obstacles = data.get("moving_obstacles") or []
        if not isinstance(obstacles, list):
            raise ValueError(f"{path}: moving_obstacles must be a list")
        waypoints = data.get("waypoints")
        robot = (
            RobotDescription.from_dict(data["robot"], str(path))
            if "robot" in data
            else RobotDescription()
        )
        origin = data.get("geodetic_origin")
        if origin is not None:
            if not (isinstance(origin, list) and len(origin) == 3
                    and all(isinstance(v, (int, float)) and math.isfinite(v) for v in origin)):
                raise ValueError(f"{path}: geodetic_origin must be [lat, lon, alt], got {origin!r}")
            origin = tuple(float(v) for v in origin)
        sensors = {}
        for name, allowed in (("imu", _IMU_KEYS), ("gnss", _GNSS_KEYS)):
            spec = data.get(name)
            if spec is None:
                continue
            if not isinstance(spec, dict) or set(spec) - allowed:
                raise ValueError(f"{path}: {name} must be a mapping with keys among "
                                 f"{sorted(allowed)}, got {spec!r}")
            sensors[name] = spec
        if "gnss" in sensors and origin is None:
            raise ValueError(f"{path}: gnss needs a geodetic_origin")
        furniture = data.get("furniture") or []
        if not isinstance(furniture, list):
            raise ValueError(f"{path}: furniture must be a list")
        boxes = [
            BoxObstacle.from_dict(spec, f"{path}: furniture[{i}]")
            for i, spec in enumerate(furniture)
        ]
        terrain = data.get("terrain")
        terrain_path, climb = None, 30.0
        if terrain is not None:
            if not (isinstance(terrain, dict) and "elevation" in terrain
                    and set(terrain) <= {"elevation", "max_climb_slope_deg"}):
                raise ValueError(f"{path}: terrain must be a mapping with 'elevation' (a gridmap "
                                 f"file) and optionally 'max_climb_slope_deg', got {terrain!r}")
            terrain_path = path.parent / str(terrain["elevation"])
            if not terrain_path.is_file():
                raise ValueError(f"{path}: terrain elevation file {terrain_path} not found")
            climb = terrain.get("max_climb_slope_deg", 30.0)
            if not (isinstance(climb, (int, float)) and 0.0 < climb < 90.0):
                raise ValueError(f"{path}: terrain.max_climb_slope_deg must be in (0, 90) deg, "
                                 f"got {climb!r}")
        robots = _robot_entries(data.get("robots"), path)
        levels = data.get("levels")
        if levels is not None:
            if terrain is not None:
                raise ValueError(f"{path}: a world has a terrain or levels, not both")
            MultiLevelWorld.from_dict(levels, f"{path}: levels")  # ValueError: malformed
            # Named after the description, not after its ground floor's map.
            world = World(world.occupied, world.resolution, world.origin_x, world.origin_y,
                          name=path.stem)
        return cls(
            world,
            map_path=map_path,
            start_pose=start_pose,
            obstacles=obstacles,
            waypoints_path=path.parent / waypoints if waypoints else None,
            source=str(path),
            robot=robot,
            geodetic_origin=origin,
            imu=sensors.get("imu"),
            gnss=sensors.get("gnss"),
            furniture=boxes,
            terrain_path=terrain_path,
            max_climb_slope_deg=float(climb),
            robots=robots,
            levels=levels,
        )


def _robot_entries(data: object, path: Path) -> list[RobotEntry]:
    """Parse a world's ``robots`` list (see :class:`WorldDescription`).

    Raises:
        ValueError: not a list of mappings with a unique ``name`` (letters, digits and ``_``,
            not starting with a digit: a ROS namespace) and a finite ``[x, y, yaw]``
            ``start_pose``, or unknown keys.
    """
    if data is None:
        return []
    if not isinstance(data, list):
        raise ValueError(f"{path}: robots must be a list, got {data!r}")
    entries = []
    for i, spec in enumerate(data):
        where = f"{path}: robots[{i}]"
        if not isinstance(spec, dict) or set(spec) - {"name", "start_pose", "waypoints"}:
            raise ValueError(f"{where} must be a mapping with keys among name, start_pose, "
                             f"waypoints, got {spec!r}")
        name = spec.get("name")
        if not (isinstance(name, str) and name.isidentifier() and name.isascii()):
            raise ValueError(f"{where}.name must be a ROS name (letters, digits, _), got {name!r}")
        start = spec.get("start_pose")
        if not (isinstance(start, list) and len(start) == 3
                and all(isinstance(v, (int, float)) and math.isfinite(v) for v in start)):
            raise ValueError(f"{where}.start_pose must be [x, y, yaw], got {start!r}")
        waypoints = spec.get("waypoints")
        entries.append(RobotEntry(name, tuple(float(v) for v in start),
                                  path.parent / waypoints if waypoints else None))
    names = [e.name for e in entries]
    if len(set(names)) != len(names):
        raise ValueError(f"{path}: robot names must be unique, got {names}")
    return entries


def load_waypoint_levels(path: str | Path) -> list[str] | None:
    """The level of each waypoint of a multi-level world's waypoint file (its ``levels``: a
    list of level names beside ``waypoints``), None when the file gives none.

    Raises:
        FileNotFoundError: no such file.
        ValueError: ``levels`` is not a list of names, one per waypoint.
    """
    path = Path(path)
    data = yaml.safe_load(path.read_text())
    if not isinstance(data, dict) or data.get("levels") is None:
        return None
    levels = data["levels"]
    count = len(data.get("waypoints") or [])
    if not (isinstance(levels, list) and len(levels) == count
            and all(isinstance(v, str) for v in levels)):
        raise ValueError(f"{path}: levels must be a list of {count} level names, one per "
                         f"waypoint, got {levels!r}")
    return list(levels)


def load_waypoints(path: str | Path) -> list[tuple[float, float, float]]:
    """Read a waypoint list: a YAML list of ``[x, y, yaw]`` (or ``{waypoints: [...]}``).

    Raises:
        FileNotFoundError: no such file.
        ValueError: an entry that is not three finite numbers (names its index), or no entry.
    """
    path = Path(path)
    data = yaml.safe_load(path.read_text())
    if isinstance(data, dict):
        data = data.get("waypoints")
    if not isinstance(data, list) or not data:
        raise ValueError(f"{path}: expected a non-empty list of [x, y, yaw]")
    result = []
    for i, entry in enumerate(data):
        try:
            x, y, yaw = (float(v) for v in entry)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{path}: waypoint {i} must be [x, y, yaw], got {entry!r}") from err
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(f"{path}: waypoint {i} is not finite: {entry!r}")
        result.append((x, y, yaw))
    return result
