"""Multi-level worlds: flat floors at different heights joined by straight ramps.

A multi-level world is described by the ``levels`` section of a world YAML (``two_floors.yaml``)::

    levels:
      resolution: 0.05              # m, the grids of walls each level's robot hits and sees
      bounds: [0.0, 0.0, 8.0, 6.0]  # x0, y0, x1, y1 of those grids
      step_height: 0.05             # m, solids lower than this above the surface are driven over
      max_climb_slope_deg: 30.0     # no ramp steeper than this can be driven up
      start_level: ground           # where the start pose is (default: the first floor)
      mesh_resolution: 0.1          # m, quads of the walkable-surface mesh (PLY)
      floors:                       # flat walkable areas: [x0, y0, x1, y1] at height z
        - {name: ground, z: 0.0, area: [0.0, 0.0, 8.0, 6.0], thickness: 0.2}
        - {name: upper, z: 1.5, area: [4.5, 3.5, 8.0, 6.0], thickness: 0.2}
      ramps:                        # straight ramps from a lower floor up to a higher one
        - {name: ramp, lower: ground, upper: upper, area: [0.5, 4.9, 4.5, 5.9], rises: +x}
      solids:                       # walls, railings, pillars, furniture: boxes
        - {name: north wall, box: [0.0, 5.9, 8.0, 6.0], z: [0.0, 3.0]}

The geometry is solids (boxes ``[x0, x1] x [y0, y1] x [z0, z1]``), floor slabs
(``[z - thickness, z]`` over the floor's area) and ramp wedges (from the lower floor's height up
to the ramp's surface over its area). The walkable surfaces, called *levels*, are the floors and
the ramps. A ramp's surface rises linearly along ``rises`` (``+x``, ``-x``, ``+y``, ``-y``) from
its lower floor's height at its foot edge to its upper floor's height at its top edge.

The robot is always on one level (:meth:`MultiLevelWorld.next_level`): it moves from a floor onto
a ramp only by crossing the ramp's foot (or top) edge, and leaves the ramp only through those two
edges; it never changes level anywhere else, so the same ``(x, y)`` may lie on two surfaces (the
ground floor under the upper floor) and the robot stays on the one it is on. A move that would
leave its level's area elsewhere is refused (``"edge of LEVEL"``; walls or railings normally stop
the robot before).

Each level has two 2D grids (:class:`World`) computed once from the geometry:

- *collision* (:meth:`collision_world`): the cells of the solids that reach into the robot's body
  on that level, heights ``[h + step_height, h + robot_height]`` above the level's surface ``h``
  at that cell (on a ramp, ``h`` is the ramp's plane extended beyond its ends). Slabs and
  wedges are not obstacles but ground: the ground floor's robot drives under the upper floor
  when its slab's underside is above the robot; a ramp's wedge is kept off the ground floor by
  the solids around it (its side walls and the wall under its top).
- *laser* (:meth:`laser_world`): the cells where the laser's scan plane (``laser_height`` above
  the level's surface, parallel to it: on a ramp the laser pitches with the robot) lies inside
  a solid, a floor slab or a ramp wedge. On the ground floor the laser sees the walls crossing
  its height and a ramp's surface where it rises above the laser; on the upper floor it sees the
  railings and the walls above it, and through a railing's gap down the ramp the ground floor's
  walls that reach its height; on a ramp it sees the ramp's side walls and what its plane meets.
  A slab whose underside is above the laser (the upper floor seen from below) is not seen.

:meth:`walkable_mesh` is a triangle mesh of the walkable surface (two triangles per
``mesh_resolution`` quad of each level's area that no solid of that level covers; a floor's
area under a ramp belongs to the ramp; vertices shared across levels where the surfaces meet:
the ramp's foot and top edges), :meth:`ply_text` the same as an ASCII PLY file.

Thread contract: immutable after construction (grids computed lazily once, from the loop
thread or before it starts); read from one thread at a time while the grids are being built.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from easynav.playground.sim.world import World

_EPS = 1e-6


@dataclass(frozen=True)
class Solid:
    """A box ``[x0, x1] x [y0, y1] x [z0, z1]`` (m, map frame): a wall, a railing, a pillar."""

    name: str
    x0: float
    y0: float
    x1: float
    y1: float
    z0: float
    z1: float


@dataclass(frozen=True)
class Floor:
    """A flat walkable area ``area = (x0, y0, x1, y1)`` at height ``z``, on a slab of
    ``thickness``."""

    name: str
    z: float
    area: tuple[float, float, float, float]
    thickness: float = 0.2

    def height(self, x, y):
        """Surface height at points (the same everywhere)."""
        return np.full(np.shape(x), self.z, dtype=float) if np.ndim(x) else self.z

    def gradient(self) -> tuple[float, float]:
        return (0.0, 0.0)


@dataclass(frozen=True)
class Ramp:
    """A straight ramp over ``area`` rising along ``rises`` from floor ``lower`` (height
    ``z_low``) at its foot edge to floor ``upper`` (``z_high``) at its top edge."""

    name: str
    lower: str
    upper: str
    area: tuple[float, float, float, float]
    rises: str
    z_low: float
    z_high: float

    @property
    def axis(self) -> int:
        """0: rises along x; 1: along y."""
        return 0 if self.rises[1] == "x" else 1

    @property
    def foot(self) -> float:
        """Coordinate (along :attr:`axis`) of the foot edge."""
        lo, hi = self.area[self.axis], self.area[self.axis + 2]
        return lo if self.rises[0] == "+" else hi

    @property
    def top(self) -> float:
        """Coordinate (along :attr:`axis`) of the top edge."""
        lo, hi = self.area[self.axis], self.area[self.axis + 2]
        return hi if self.rises[0] == "+" else lo

    @property
    def slope(self) -> float:
        """Inclination (rad)."""
        return math.atan2(self.z_high - self.z_low, abs(self.top - self.foot))

    def t(self, x, y):
        """Position along the ramp: 0 at the foot edge, 1 at the top edge (unclipped)."""
        u = x if self.axis == 0 else y
        return (np.asarray(u, dtype=float) - self.foot) / (self.top - self.foot)

    def across(self, x, y) -> bool:
        """Whether ``(x, y)`` is within the ramp's width (across its axis)."""
        c = y if self.axis == 0 else x
        lo, hi = self.area[1 - self.axis], self.area[3 - self.axis]
        return lo - _EPS <= c <= hi + _EPS

    def height(self, x, y):
        """The ramp's plane at points (extended linearly beyond its ends)."""
        z = self.z_low + self.t(x, y) * (self.z_high - self.z_low)
        return z if np.ndim(z) else float(z)

    def gradient(self) -> tuple[float, float]:
        g = (self.z_high - self.z_low) / (self.top - self.foot)
        return (g, 0.0) if self.axis == 0 else (0.0, g)


def _area(value: object, where: str) -> tuple[float, float, float, float]:
    try:
        x0, y0, x1, y1 = (float(v) for v in value)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{where}: must be [x0, y0, x1, y1], got {value!r}") from err
    if not (all(math.isfinite(v) for v in (x0, y0, x1, y1)) and x0 < x1 and y0 < y1):
        raise ValueError(f"{where}: need finite x0 < x1 and y0 < y1, got {value!r}")
    return (x0, y0, x1, y1)


def _check_keys(spec: object, allowed: set[str], required: set[str], where: str) -> dict:
    if not isinstance(spec, dict):
        raise ValueError(f"{where}: must be a mapping, got {spec!r}")
    unknown = set(spec) - allowed
    missing = required - set(spec)
    if unknown or missing:
        raise ValueError(f"{where}: unknown keys {sorted(unknown)}, missing {sorted(missing)}")
    return spec


class MultiLevelWorld:
    """Floors, ramps and solids (see the module documentation); the robot's geometry
    (``robot_height``, ``laser_height`` above the surface) sets what each level hits and sees.

    Raises:
        ValueError: no floor, duplicate level names, a ramp naming an unknown floor or not
            rising, a ramp steeper than 89 deg, bad numbers (each message names the entry).
    """

    def __init__(
        self,
        floors: list[Floor],
        ramps: list[Ramp],
        solids: list[Solid],
        resolution: float,
        bounds: tuple[float, float, float, float],
        step_height: float = 0.05,
        max_climb_slope_deg: float = 30.0,
        start_level: str | None = None,
        mesh_resolution: float = 0.1,
        robot_height: float = 0.5,
        laser_height: float = 0.25,
        name: str = "",
    ) -> None:
        if not floors:
            raise ValueError(f"MultiLevelWorld '{name}': needs at least one floor")
        names = [f.name for f in floors] + [r.name for r in ramps]
        if len(set(names)) != len(names):
            raise ValueError(f"MultiLevelWorld '{name}': level names must be unique, got {names}")
        floor_names = {f.name for f in floors}
        for r in ramps:
            if r.lower not in floor_names or r.upper not in floor_names:
                raise ValueError(f"ramp '{r.name}': lower/upper must be floors of {floor_names}")
            if r.z_high <= r.z_low:
                raise ValueError(f"ramp '{r.name}': its upper floor must be higher than its lower")
        for label, value in (("resolution", resolution), ("mesh_resolution", mesh_resolution),
                             ("robot_height", robot_height), ("laser_height", laser_height)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"MultiLevelWorld '{name}': {label} must be > 0, got {value}")
        if not (0.0 < max_climb_slope_deg < 90.0):
            raise ValueError(f"MultiLevelWorld '{name}': max_climb_slope_deg must be in (0, 90)")
        if not (math.isfinite(step_height) and step_height >= 0.0):
            raise ValueError(f"MultiLevelWorld '{name}': step_height must be >= 0")
        self.floors = list(floors)
        self.ramps = list(ramps)
        self.solids = list(solids)
        self.resolution = float(resolution)
        self.bounds = tuple(float(v) for v in bounds)
        self.step_height = float(step_height)
        self.max_climb_slope_deg = float(max_climb_slope_deg)
        self.max_climb_slope = math.radians(self.max_climb_slope_deg)
        self.start_level = start_level if start_level is not None else floors[0].name
        if self.start_level not in floor_names:
            raise ValueError(f"MultiLevelWorld '{name}': start_level must be a floor, got "
                             f"{self.start_level!r}")
        self.mesh_resolution = float(mesh_resolution)
        self.robot_height = float(robot_height)
        self.laser_height = float(laser_height)
        self.name = name
        self._surfaces: dict[str, Floor | Ramp] = {s.name: s for s in [*floors, *ramps]}
        self._collision: dict[str, World] = {}
        self._laser: dict[str, World] = {}

    # ------------------------------------------------------------------ loading
    @classmethod
    def from_dict(cls, spec: object, where: str = "levels", robot_height: float = 0.5,
                  laser_height: float = 0.25, name: str = "") -> MultiLevelWorld:
        """Parse a world's ``levels`` section (see the module documentation).

        Raises:
            ValueError: a malformed section (names the entry).
        """
        spec = _check_keys(
            spec, {"resolution", "bounds", "step_height", "max_climb_slope_deg", "start_level",
                   "mesh_resolution", "floors", "ramps", "solids"},
            {"floors", "bounds"}, where)
        floors = []
        for i, f in enumerate(spec["floors"] or []):
            w = f"{where}.floors[{i}]"
            _check_keys(f, {"name", "z", "area", "thickness"}, {"name", "z", "area"}, w)
            floors.append(Floor(str(f["name"]), float(f["z"]), _area(f["area"], f"{w}.area"),
                                float(f.get("thickness", 0.2))))
        heights = {f.name: f.z for f in floors}
        ramps = []
        for i, r in enumerate(spec.get("ramps") or []):
            w = f"{where}.ramps[{i}]"
            _check_keys(r, {"name", "lower", "upper", "area", "rises"},
                        {"name", "lower", "upper", "area", "rises"}, w)
            if r["rises"] not in ("+x", "-x", "+y", "-y"):
                raise ValueError(f"{w}.rises must be +x, -x, +y or -y, got {r['rises']!r}")
            if r["lower"] not in heights or r["upper"] not in heights:
                raise ValueError(f"{w}: lower and upper must name floors ({sorted(heights)})")
            ramps.append(Ramp(str(r["name"]), str(r["lower"]), str(r["upper"]),
                              _area(r["area"], f"{w}.area"), str(r["rises"]),
                              heights[r["lower"]], heights[r["upper"]]))
        solids = []
        for i, s in enumerate(spec.get("solids") or []):
            w = f"{where}.solids[{i}]"
            _check_keys(s, {"name", "box", "z"}, {"box", "z"}, w)
            x0, y0, x1, y1 = _area(s["box"], f"{w}.box")
            z0, z1 = (float(v) for v in s["z"])
            if not z0 < z1:
                raise ValueError(f"{w}.z: need z0 < z1, got {s['z']!r}")
            solids.append(Solid(str(s.get("name", f"solid {i}")), x0, y0, x1, y1, z0, z1))
        return cls(
            floors, ramps, solids,
            resolution=float(spec.get("resolution", 0.05)),
            bounds=_area(spec["bounds"], f"{where}.bounds"),
            step_height=float(spec.get("step_height", 0.05)),
            max_climb_slope_deg=float(spec.get("max_climb_slope_deg", 30.0)),
            start_level=spec.get("start_level"),
            mesh_resolution=float(spec.get("mesh_resolution", 0.1)),
            robot_height=robot_height, laser_height=laser_height, name=name,
        )

    @classmethod
    def from_description_file(cls, path: str | Path, robot_height: float = 0.5,
                              laser_height: float = 0.25) -> MultiLevelWorld:
        """The ``levels`` section of a world description YAML."""
        path = Path(path)
        data = yaml.safe_load(path.read_text())
        if not isinstance(data, dict) or "levels" not in data:
            raise ValueError(f"{path}: no 'levels' section")
        return cls.from_dict(data["levels"], f"{path}: levels", robot_height, laser_height,
                             name=path.stem)

    # ------------------------------------------------------------------ levels
    @property
    def level_names(self) -> list[str]:
        """Floors, then ramps."""
        return list(self._surfaces)

    def surface(self, level: str) -> Floor | Ramp:
        """The floor or ramp named ``level``.

        Raises:
            KeyError: no such level.
        """
        return self._surfaces[level]

    def height(self, level: str, x: float, y: float) -> float:
        """Height (m) of ``level``'s surface at ``(x, y)`` (a ramp's plane extended)."""
        return float(self._surfaces[level].height(x, y))

    def slope(self, level: str) -> float:
        """Inclination (rad) of ``level`` (0 on a floor)."""
        s = self._surfaces[level]
        return s.slope if isinstance(s, Ramp) else 0.0

    def attitude(self, level: str, yaw: float) -> tuple[float, float]:
        """``(pitch, roll)`` (rad, REP-103: about the robot's y and x axes) of a robot heading
        ``yaw`` on ``level``: driving up a ramp the nose rises, a negative pitch."""
        gx, gy = self._surfaces[level].gradient()
        forward = gx * math.cos(yaw) + gy * math.sin(yaw)
        left = -gx * math.sin(yaw) + gy * math.cos(yaw)
        return -math.atan(forward) + 0.0, math.atan(left) + 0.0

    def in_area(self, level: str, x: float, y: float) -> bool:
        """Whether ``(x, y)`` is within ``level``'s area (edges included)."""
        x0, y0, x1, y1 = self._surfaces[level].area
        return x0 - _EPS <= x <= x1 + _EPS and y0 - _EPS <= y <= y1 + _EPS

    def next_level(self, level: str, x0: float, y0: float, x1: float, y1: float) -> str | None:
        """The level a robot on ``level`` is on after moving from ``(x0, y0)`` to
        ``(x1, y1)``: a ramp's level once it crossed the ramp's foot edge from the lower floor
        (or its top edge from the upper floor) within the ramp's width, that floor again once it
        crossed back; else ``level`` when ``(x1, y1)`` is still in its area, None when the move
        leaves it (a fall off an edge: refused)."""
        surface = self._surfaces[level]
        if isinstance(surface, Ramp):
            t1 = float(surface.t(x1, y1))
            if not surface.across(x1, y1):
                return None
            if t1 < 0.0:
                return surface.lower if self.in_area(surface.lower, x1, y1) else None
            if t1 > 1.0:
                return surface.upper if self.in_area(surface.upper, x1, y1) else None
            return level
        for ramp in self.ramps:
            t0, t1 = float(ramp.t(x0, y0)), float(ramp.t(x1, y1))
            if not ramp.across(x1, y1):
                continue
            if ramp.lower == level and t0 < 0.0 <= t1:
                return ramp.name
            if ramp.upper == level and t0 > 1.0 >= t1:
                return ramp.name
        return level if self.in_area(level, x1, y1) else None

    def level_at(self, x: float, y: float, z: float) -> str | None:
        """The level whose surface at ``(x, y)`` is nearest height ``z`` (within 0.3 m), None
        when no level's area holds the point."""
        best, gap = None, 0.3
        for name in self._surfaces:
            if self.in_area(name, x, y):
                d = abs(self.height(name, x, y) - z)
                if d <= gap:
                    best, gap = name, d
        return best

    def surface_step(self, level: str, x0: float, y0: float, x1: float,
                     y1: float) -> tuple[float, float]:
        """Where a wheel motion from ``(x0, y0)`` planned as ``(x1, y1)`` on flat ground ends on
        ``level``'s surface: the same distance along it (on a slope of pitch p the horizontal
        advance shrinks by cos p), as :meth:`Terrain.surface_step`."""
        dx, dy = x1 - x0, y1 - y0
        ds = math.hypot(dx, dy)
        if ds == 0.0:
            return x1, y1
        dz = self.height(level, x1, y1) - self.height(level, x0, y0)
        k = ds / math.hypot(ds, dz)
        return x0 + k * dx, y0 + k * dy

    def blocks(self, level: str, target: str, x0: float, y0: float, x1: float,
               y1: float) -> float | None:
        """The slope (rad) that stops a move onto ``target`` (from ``level``), or None: a move
        that gains height on a ramp steeper than :attr:`max_climb_slope`."""
        slope = self.slope(target)
        if slope <= self.max_climb_slope:
            return None
        if self.height(target, x1, y1) <= self.height(level, x0, y0):
            return None
        return slope

    # ------------------------------------------------------------------ grids
    def _grid(self) -> tuple[np.ndarray, np.ndarray, tuple[int, int]]:
        """Cell-centre coordinates of the levels' grids."""
        bx0, by0, bx1, by1 = self.bounds
        w = int(round((bx1 - bx0) / self.resolution))
        h = int(round((by1 - by0) / self.resolution))
        xs = bx0 + (np.arange(w) + 0.5) * self.resolution
        ys = by0 + (np.arange(h) + 0.5) * self.resolution
        gx, gy = np.meshgrid(xs, ys)
        return gx, gy, (h, w)

    def _cells(self, box: tuple[float, float, float, float]) -> tuple[slice, slice]:
        """Rows and columns of the cells whose square overlaps ``box``'s interior."""
        bx0, by0, bx1, by1 = self.bounds
        r = self.resolution
        x0, y0, x1, y1 = box
        c0 = max(0, math.floor((x0 - bx0) / r + _EPS))
        c1 = max(0, math.ceil((x1 - bx0) / r - _EPS))
        r0 = max(0, math.floor((y0 - by0) / r + _EPS))
        r1 = max(0, math.ceil((y1 - by0) / r - _EPS))
        return slice(r0, r1), slice(c0, c1)

    def _world(self, grid: np.ndarray, level: str, what: str) -> World:
        return World(grid, self.resolution, self.bounds[0], self.bounds[1],
                     name=f"{self.name} {level} {what}".strip())

    def collision_world(self, level: str) -> World:
        """The walls the robot's body on ``level`` hits (see the module documentation)."""
        if level not in self._collision:
            gx, gy, shape = self._grid()
            plane = self._surfaces[level].height(gx, gy)
            grid = np.zeros(shape, dtype=bool)
            for s in self.solids:
                rows, cols = self._cells((s.x0, s.y0, s.x1, s.y1))
                h = plane[rows, cols]
                grid[rows, cols] |= (h + self.step_height <= s.z1) & (h + self.robot_height >= s.z0)
            self._collision[level] = self._world(grid, level, "collision")
        return self._collision[level]

    def laser_world(self, level: str) -> World:
        """What the laser of a robot on ``level`` sees (see the module documentation)."""
        if level not in self._laser:
            gx, gy, shape = self._grid()
            plane = self._surfaces[level].height(gx, gy) + self.laser_height
            grid = np.zeros(shape, dtype=bool)
            for s in self.solids:
                rows, cols = self._cells((s.x0, s.y0, s.x1, s.y1))
                p = plane[rows, cols]
                grid[rows, cols] |= (p >= s.z0) & (p <= s.z1)
            for f in self.floors:
                rows, cols = self._cells(f.area)
                p = plane[rows, cols]
                grid[rows, cols] |= (p >= f.z - f.thickness) & (p <= f.z)
            for ramp in self.ramps:
                rows, cols = self._cells(ramp.area)
                p = plane[rows, cols]
                top = ramp.height(gx[rows, cols], gy[rows, cols])
                grid[rows, cols] |= (p >= ramp.z_low) & (p <= top)
            self._laser[level] = self._world(grid, level, "laser")
        return self._laser[level]

    # ------------------------------------------------------------------ mesh
    def walkable_mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """``(vertices (n, 3) float, faces (m, 3) int)``: the walkable surface as triangles
        (see the module documentation), counter-clockwise seen from above."""
        step = self.mesh_resolution
        index: dict[tuple[int, int, int], int] = {}
        vertices: list[tuple[float, float, float]] = []
        faces: list[tuple[int, int, int]] = []

        def vertex(x: float, y: float, z: float) -> int:
            key = (round(x * 1e4), round(y * 1e4), round(z * 1e4))
            if key not in index:
                index[key] = len(vertices)
                vertices.append((key[0] / 1e4, key[1] / 1e4, key[2] / 1e4))
            return index[key]

        for level, surface in self._surfaces.items():
            walls = self.collision_world(level)
            x0, y0, x1, y1 = surface.area
            nx, ny = int(round((x1 - x0) / step)), int(round((y1 - y0) / step))
            for j in range(ny):
                for i in range(nx):
                    qx0, qy0 = x0 + i * step, y0 + j * step
                    qx1, qy1 = qx0 + step, qy0 + step
                    cx, cy = qx0 + 0.5 * step, qy0 + 0.5 * step
                    if isinstance(surface, Floor) and self._under_ramp(level, cx, cy):
                        continue
                    rows, cols = self._cells((qx0, qy0, qx1, qy1))
                    if walls.occupied[rows, cols].any():
                        continue
                    corners = [(qx0, qy0), (qx1, qy0), (qx1, qy1), (qx0, qy1)]
                    ids = [vertex(x, y, self.height(level, x, y)) for x, y in corners]
                    faces.append((ids[0], ids[1], ids[2]))
                    faces.append((ids[0], ids[2], ids[3]))
        return np.array(vertices, dtype=float), np.array(faces, dtype=int)

    def _under_ramp(self, level: str, x: float, y: float) -> bool:
        """Whether ``(x, y)`` of floor ``level`` lies under (or is) a ramp's area."""
        return any(self.in_area(r.name, x, y) for r in self.ramps)

    def ply_text(self, comment: str = "") -> str:
        """:meth:`walkable_mesh` as an ASCII PLY file (x, y, z float vertices; triangles)."""
        vertices, faces = self.walkable_mesh()
        lines = ["ply", "format ascii 1.0"]
        if comment:
            lines += [f"comment {c}" for c in comment.splitlines()]
        lines += [f"element vertex {len(vertices)}", "property float x", "property float y",
                  "property float z", f"element face {len(faces)}",
                  "property list uchar int vertex_indices", "end_header"]
        lines += [f"{x:.4f} {y:.4f} {z:.4f}" for x, y, z in vertices]
        lines += [f"3 {a} {b} {c}" for a, b, c in faces]
        return "\n".join(lines) + "\n"


def read_ply(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices, faces)`` of an ASCII PLY file of triangles (what :meth:`ply_text`
    writes).

    Raises:
        ValueError: not an ASCII PLY of x y z vertices and triangles.
    """
    lines = Path(path).read_text().splitlines()
    if not lines or lines[0] != "ply" or lines[1] != "format ascii 1.0":
        raise ValueError(f"{path}: not an ASCII PLY file")
    end = lines.index("end_header")
    counts = {}
    for line in lines[:end]:
        if line.startswith("element "):
            _, name, n = line.split()
            counts[name] = int(n)
    nv, nf = counts.get("vertex", 0), counts.get("face", 0)
    body = lines[end + 1:]
    vertices = np.array([[float(v) for v in ln.split()[:3]] for ln in body[:nv]], dtype=float)
    faces = []
    for ln in body[nv:nv + nf]:
        values = [int(v) for v in ln.split()]
        if values[0] != 3:
            raise ValueError(f"{path}: only triangles are read, got a face of {values[0]}")
        faces.append(values[1:4])
    return vertices.reshape(-1, 3), np.array(faces, dtype=int).reshape(-1, 3)


def write_multilevel_files(description: str | Path, out_dir: str | Path | None = None
                           ) -> list[Path]:
    """Write what a multi-level world description generates into ``out_dir`` (default: beside
    it): the walkable-surface mesh ``<stem>.walkable.ply`` and a 2D map of each floor
    (``maps/<stem>_<floor>.yaml`` + PGM: what that floor's laser sees). Returns the paths
    written."""
    description = Path(description)
    out = Path(out_dir) if out_dir is not None else description.parent
    levels = MultiLevelWorld.from_description_file(description)
    stem = description.stem
    written = []
    ply = out / f"{stem}.walkable.ply"
    ply.write_text(levels.ply_text(
        f"walkable surface of the {stem} world, generated from {description.name} by "
        "easynav.playground.sim.multilevel"))
    written.append(ply)
    maps = out / "maps"
    maps.mkdir(parents=True, exist_ok=True)
    for floor in levels.floors:
        world = levels.laser_world(floor.name)
        written.append(world.save_map_server_yaml(maps / f"{stem}_{floor.name}.yaml"))
        written.append(maps / f"{stem}_{floor.name}.pgm")
    return written


if __name__ == "__main__":
    import sys

    from easynav.playground.world_description import WORLDS_DIR

    target = sys.argv[1] if len(sys.argv) > 1 else WORLDS_DIR / "two_floors.yaml"
    for p in write_multilevel_files(target):
        print(p)
