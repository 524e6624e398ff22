"""RobotDescription: the robot a world declares (radius, base limits, laser)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from easynav.playground.sim.base_limits import BaseLimits

#: Keys of the ``laser`` section (each is the playground node parameter ``laser.<key>``).
LASER_KEYS = (
    "beams",
    "fov",
    "min_range",
    "max_range",
    "rate",
    "noise_std",
    "x",
    "y",
    "z",
    "yaw",
)
#: Keys of the ``lidar`` section (each is the playground node parameter ``lidar.<key>``).
LIDAR_KEYS = (
    "rings",
    "beams",
    "min_elevation",
    "max_elevation",
    "min_range",
    "max_range",
    "rate",
    "noise_std",
    "x",
    "y",
    "z",
    "yaw",
)
#: The playground's robot when a world declares none (its parameter defaults).
DEFAULT_RADIUS = 0.2


@dataclass(frozen=True)
class RobotDescription:
    """The robot of a world: ``radius`` (m), ``limits`` (the base's :class:`BaseLimits` keys
    that differ from the defaults) and ``laser`` (``laser.*`` playground parameters).

    In a world description::

        robot:
          radius: 0.15                                   # collision disc (m)
          limits: {max_linear_vel: 0.3, max_angular_vel: 1.8}
          laser: {beams: 360, max_range: 3.5}
          height: 0.5                                    # top of the robot (m): collisions
          lidar: {rings: 16, max_range: 8.0}             # a 3D lidar (none without the key)

    The playground takes them as the defaults of its ``robot_radius``, ``base.*`` and
    ``laser.*`` parameters (an explicit parameter still wins); the demo writes ``radius`` into
    ``system_node.robot_geometry.radius`` of the params it derives.

    Thread contract: an immutable value.
    """

    radius: float = DEFAULT_RADIUS
    limits: dict[str, float] = field(default_factory=dict)
    laser: dict[str, float] = field(default_factory=dict)
    declared: bool = False
    height: float | None = None  # None: not declared (the playground's robot_height default)
    lidar: dict[str, float] | None = None

    @classmethod
    def from_dict(cls, data: object, source: str) -> RobotDescription:
        """Parse a ``robot`` section.

        Raises:
            ValueError: not a mapping, unknown keys, or a value that is not a finite positive
                number (``laser.x/y/z/yaw`` may be any finite number); names ``source`` and the
                key.
        """
        if not isinstance(data, dict):
            raise ValueError(f"{source}: robot must be a mapping, got {data!r}")
        unknown = set(data) - {"radius", "limits", "laser", "height", "lidar"}
        if unknown:
            raise ValueError(f"{source}: robot has unknown keys {sorted(unknown)}")
        radius = _number(data.get("radius", DEFAULT_RADIUS), f"{source}: robot.radius")
        if radius <= 0.0:
            raise ValueError(f"{source}: robot.radius must be > 0, got {radius}")
        limits = _section(data.get("limits") or {}, BaseLimits.__slots__, "limits", source)
        BaseLimits(**limits)  # validates each limit (> 0), naming it
        laser = _section(data.get("laser") or {}, LASER_KEYS, "laser", source)
        for key in ("beams", "fov", "max_range", "rate"):
            if key in laser and laser[key] <= 0.0:
                raise ValueError(f"{source}: robot.laser.{key} must be > 0, got {laser[key]}")
        for key in ("min_range", "noise_std"):
            if key in laser and laser[key] < 0.0:
                raise ValueError(f"{source}: robot.laser.{key} must be >= 0, got {laser[key]}")
        if "beams" in laser:
            if not float(laser["beams"]).is_integer():
                raise ValueError(f"{source}: robot.laser.beams must be an integer")
            laser["beams"] = int(laser["beams"])
        height = None
        if "height" in data:
            height = _number(data["height"], f"{source}: robot.height")
            if height <= 0.0:
                raise ValueError(f"{source}: robot.height must be > 0, got {height}")
        lidar = None
        if "lidar" in data:
            lidar = _section(data.get("lidar") or {}, LIDAR_KEYS, "lidar", source)
            for key in ("rings", "beams"):
                if key in lidar:
                    if not float(lidar[key]).is_integer() or lidar[key] < 1:
                        raise ValueError(f"{source}: robot.lidar.{key} must be an integer >= 1")
                    lidar[key] = int(lidar[key])
        return cls(radius, limits, laser, declared=True, height=height, lidar=lidar)

    def parameter_defaults(self) -> dict[str, object]:
        """The playground node parameters this robot sets (``robot_radius``, ``base.*``,
        ``laser.*``); empty for an undeclared robot."""
        if not self.declared:
            return {}
        values: dict[str, object] = {"robot_radius": self.radius}
        if self.height is not None:
            values["robot_height"] = self.height
        values.update({f"base.{k}": v for k, v in self.limits.items()})
        values.update({f"laser.{k}": v for k, v in self.laser.items()})
        if self.lidar is not None:
            values["lidar.enabled"] = True
            values.update({f"lidar.{k}": v for k, v in self.lidar.items()})
        return values


def _number(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value}")
    return value


def _section(data: object, keys, what: str, source: str) -> dict[str, float]:
    if not isinstance(data, dict):
        raise ValueError(f"{source}: robot.{what} must be a mapping, got {data!r}")
    unknown = set(data) - set(keys)
    if unknown:
        raise ValueError(
            f"{source}: robot.{what} has unknown keys {sorted(unknown)} (known: {list(keys)})"
        )
    return {k: _number(v, f"{source}: robot.{what}.{k}") for k, v in data.items()}
