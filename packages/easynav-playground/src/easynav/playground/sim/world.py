"""World: the simulator's ground-truth occupancy grid, in metres."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml


class World:
    """A binary occupancy grid: the truth the simulated robot moves in and its laser sees.

    ``occupied[y, x]`` is cell ``(x, y)``; cell ``(0, 0)`` has its lower-left corner at
    ``(origin_x, origin_y)`` and cell centres are at ``origin + (i + 0.5) * resolution``
    (the original EasyNav's ``.map`` convention). Space outside the grid is free: rays leave
    the world without a return.

    Thread contract: immutable after construction; any thread may read it.

    Raises:
        ValueError: the grid is not 2-D, is empty, or the resolution is not finite and > 0.
    """

    def __init__(
        self,
        occupied: np.ndarray,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        name: str = "",
    ) -> None:
        grid = np.asarray(occupied)
        if grid.ndim != 2 or grid.size == 0:
            raise ValueError(
                f"World '{name}': the grid must be 2-D and non-empty, got {grid.shape}"
            )
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f"World '{name}': resolution must be finite and > 0, got {resolution}")
        if not (math.isfinite(origin_x) and math.isfinite(origin_y)):
            raise ValueError(f"World '{name}': origin must be finite, got {(origin_x, origin_y)}")
        self._occupied = np.ascontiguousarray(grid.astype(bool))
        self._occupied.flags.writeable = False
        self.resolution = float(resolution)
        self.origin_x = float(origin_x)
        self.origin_y = float(origin_y)
        self.name = name

    # ------------------------------------------------------------------ geometry
    @property
    def occupied(self) -> np.ndarray:
        """Read-only ``(height, width)`` bool array, row = y cell, column = x cell."""
        return self._occupied

    @property
    def width(self) -> int:
        """Cells along x."""
        return self._occupied.shape[1]

    @property
    def height(self) -> int:
        """Cells along y."""
        return self._occupied.shape[0]

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(min_x, min_y, max_x, max_y)`` of the grid in metres."""
        return (
            self.origin_x,
            self.origin_y,
            self.origin_x + self.width * self.resolution,
            self.origin_y + self.height * self.resolution,
        )

    def world_to_cell(self, x: np.ndarray | float, y: np.ndarray | float):
        """Cell indices ``(ix, iy)`` (floor; may be outside the grid) of metric points."""
        ix = np.floor((np.asarray(x, dtype=float) - self.origin_x) / self.resolution).astype(int)
        iy = np.floor((np.asarray(y, dtype=float) - self.origin_y) / self.resolution).astype(int)
        return ix, iy

    def cell_centre(self, ix: np.ndarray | int, iy: np.ndarray | int):
        """Metric centre ``(x, y)`` of cells."""
        return (
            self.origin_x + (np.asarray(ix) + 0.5) * self.resolution,
            self.origin_y + (np.asarray(iy) + 0.5) * self.resolution,
        )

    def is_occupied_at(self, x: np.ndarray | float, y: np.ndarray | float) -> np.ndarray:
        """Whether the cell holding each point is occupied (outside the grid: False)."""
        ix, iy = self.world_to_cell(x, y)
        inside = (ix >= 0) & (iy >= 0) & (ix < self.width) & (iy < self.height)
        result = np.zeros(np.shape(ix), dtype=bool)
        result[inside] = self._occupied[iy[inside], ix[inside]]
        return result

    def distance_to_occupied(self, x: float, y: float, max_distance: float) -> float:
        """Exact distance (m) from a point to the nearest occupied cell's square.

        Only cells within ``max_distance`` are examined: the result is ``max_distance`` when
        none is nearer. 0.0 when the point lies in an occupied cell.
        """
        res = self.resolution
        span = int(math.ceil(max_distance / res)) + 1
        cx, cy = self.world_to_cell(x, y)
        x0, x1 = max(int(cx) - span, 0), min(int(cx) + span + 1, self.width)
        y0, y1 = max(int(cy) - span, 0), min(int(cy) + span + 1, self.height)
        if x0 >= x1 or y0 >= y1:
            return float(max_distance)
        rows, cols = np.nonzero(self._occupied[y0:y1, x0:x1])
        if rows.size == 0:
            return float(max_distance)
        min_x = self.origin_x + (cols + x0) * res
        min_y = self.origin_y + (rows + y0) * res
        # Distance from a point to an axis-aligned square: clamp the point into the square.
        dx = np.maximum(np.maximum(min_x - x, 0.0), x - (min_x + res))
        dy = np.maximum(np.maximum(min_y - y, 0.0), y - (min_y + res))
        return float(min(np.sqrt(dx * dx + dy * dy).min(), max_distance))

    # ------------------------------------------------------------------ loading
    @classmethod
    def load(cls, path: str | Path) -> World:
        """Load a ``.map`` text file or a ROS map-server YAML (+ image), chosen by suffix.

        Raises:
            ValueError: unknown suffix or malformed file (the message names the file).
            FileNotFoundError: the file (or the YAML's image) does not exist.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".map":
            return cls.from_map_file(path)
        if suffix in (".yaml", ".yml"):
            return cls.from_ros_map_yaml(path)
        raise ValueError(f"{path}: unknown world file type (expected .map or a map-server .yaml)")

    @classmethod
    def from_map_file(cls, path: str | Path) -> World:
        """Load the ``.map`` text format of the original EasyNav's simple stack.

        First line ``width height resolution origin_x origin_y``, then ``width*height`` values
        0/1, row-major with y as the row.

        Raises:
            FileNotFoundError: no such file.
            ValueError: a malformed header, a value other than 0/1, or a wrong value count.
        """
        path = Path(path)
        text = path.read_text()
        return cls.from_map_text(text, name=path.stem, source=str(path))

    @classmethod
    def from_map_text(cls, text: str, name: str = "", source: str = "<text>") -> World:
        """Parse the ``.map`` format from a string (see :meth:`from_map_file`)."""
        header, _, body = text.partition("\n")
        fields = header.split()
        if len(fields) != 5:
            raise ValueError(
                f"{source}: first line must be 'width height resolution origin_x origin_y', "
                f"got {header!r}"
            )
        try:
            width, height = int(fields[0]), int(fields[1])
            resolution, origin_x, origin_y = (float(f) for f in fields[2:])
        except ValueError as err:
            raise ValueError(f"{source}: malformed header {header!r}: {err}") from err
        if width <= 0 or height <= 0:
            raise ValueError(f"{source}: width and height must be > 0, got {width}x{height}")
        values = np.array(body.split(), dtype=object)
        if values.size != width * height:
            raise ValueError(
                f"{source}: expected {width}*{height}={width * height} cell values, "
                f"found {values.size}"
            )
        bad = ~np.isin(values, ("0", "1"))
        if bad.any():
            first = int(np.argmax(bad))
            raise ValueError(
                f"{source}: cell value #{first} is {values[first]!r}; only 0 and 1 are allowed"
            )
        grid = (values == "1").reshape(height, width)
        return cls(grid, resolution, origin_x, origin_y, name=name)

    @classmethod
    def from_ros_map_yaml(cls, path: str | Path, unknown_is_occupied: bool = True) -> World:
        """Load a ROS map-server map: YAML (``image``, ``resolution``, ``origin``, ``negate``,
        ``occupied_thresh``, ``free_thresh``, ``mode``) and its PGM/PNG image.

        Occupancy follows map_server: ``p = (255 - v) / 255`` (``v / 255`` with ``negate``);
        trinary/scale modes mark ``p > occupied_thresh`` occupied and ``p < free_thresh`` free;
        raw mode takes ``v`` as the occupancy in percent (``v > 100`` is unknown). Unknown cells
        are occupied by default: a simulator needs a definite world, and unknown space in a
        recorded map is usually outside its walls.

        Raises:
            FileNotFoundError: the YAML or its image is missing.
            ValueError: a required key is missing or out of range, or the origin is rotated.
        """
        import cv2  # heavy import kept local: only map-server maps need it

        path = Path(path)
        spec = yaml.safe_load(path.read_text())
        if not isinstance(spec, dict):
            raise ValueError(f"{path}: not a map-server YAML (top level is not a mapping)")
        for key in ("image", "resolution", "origin"):
            if key not in spec:
                raise ValueError(f"{path}: missing key '{key}'")
        origin = [float(v) for v in spec["origin"]]
        if len(origin) < 2:
            raise ValueError(f"{path}: origin must be [x, y, yaw], got {spec['origin']}")
        if len(origin) > 2 and abs(origin[2]) > 1e-9:
            raise ValueError(f"{path}: rotated map origins (yaw {origin[2]}) are not supported")
        image_path = Path(spec["image"])
        if not image_path.is_absolute():
            image_path = path.parent / image_path
        if not image_path.exists():
            raise FileNotFoundError(f"{path}: image {image_path} not found")
        image = cv2.imread(str(image_path), cv2.IMREAD_UNCHANGED)
        if image is None:
            raise ValueError(f"{path}: could not decode image {image_path}")
        if image.ndim == 3:
            # map_server averages the colour channels and ignores alpha.
            image = image[:, :, :3].mean(axis=2)
        values = image.astype(float)
        if image.dtype == np.uint16:
            values = values / 257.0
        mode = str(spec.get("mode", "trinary"))
        negate = bool(int(spec.get("negate", 0)))
        occupied_thresh = float(spec.get("occupied_thresh", 0.65))
        free_thresh = float(spec.get("free_thresh", 0.25))
        if not 0.0 <= free_thresh <= occupied_thresh <= 1.0:
            raise ValueError(
                f"{path}: need 0 <= free_thresh ({free_thresh}) <= occupied_thresh "
                f"({occupied_thresh}) <= 1"
            )
        if mode == "raw":
            occupied = (values > occupied_thresh * 100.0) & (values <= 100.0)
            unknown = values > 100.0
        elif mode in ("trinary", "scale"):
            p = values / 255.0 if negate else (255.0 - values) / 255.0
            occupied = p > occupied_thresh
            unknown = ~occupied & ~(p < free_thresh)
        else:
            raise ValueError(f"{path}: unknown mode {mode!r} (trinary, scale or raw)")
        grid = occupied | (unknown if unknown_is_occupied else False)
        # Image row 0 is the top of the map; grid row 0 is the bottom (y = origin_y).
        return cls(np.flipud(grid), float(spec["resolution"]), origin[0], origin[1], name=path.stem)

    # ------------------------------------------------------------------ saving
    def to_map_text(self) -> str:
        """The world in the ``.map`` format: a header line, then all values on one line."""
        header = (
            f"{self.width} {self.height} {self.resolution!r} {self.origin_x!r} {self.origin_y!r}"
        )
        body = " ".join(np.where(self._occupied.ravel(), "1", "0"))
        return f"{header}\n{body}\n"

    def save_map_file(self, path: str | Path) -> None:
        """Write the world as a ``.map`` file (loadable by SimpleMapsManager)."""
        Path(path).write_text(self.to_map_text())

    def save_map_server_yaml(self, path: str | Path) -> Path:
        """Write the world as a ROS map-server map: ``path`` (YAML, trinary) and a PGM beside it
        (same stem; occupied 0, free 254, as map_saver writes). Returns the YAML path.

        Loadable by :meth:`from_ros_map_yaml` (same grid) and by any map-server loader
        (CostmapMapsManager).
        """
        import cv2  # heavy import kept local, as in from_ros_map_yaml

        path = Path(path)
        image_path = path.with_suffix(".pgm")
        image = np.where(np.flipud(self._occupied), 0, 254).astype(np.uint8)
        if not cv2.imwrite(str(image_path), image):
            raise OSError(f"could not write {image_path}")
        spec = {
            "image": image_path.name,
            "mode": "trinary",
            "resolution": self.resolution,
            "origin": [self.origin_x, self.origin_y, 0.0],
            "negate": 0,
            "occupied_thresh": 0.65,
            "free_thresh": 0.25,
        }
        path.write_text(yaml.safe_dump(spec, sort_keys=False))
        return path

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, World):
            return NotImplemented
        return (
            self._occupied.shape == other._occupied.shape
            and bool(np.array_equal(self._occupied, other._occupied))
            and math.isclose(self.resolution, other.resolution, rel_tol=1e-9)
            and math.isclose(self.origin_x, other.origin_x, abs_tol=1e-9)
            and math.isclose(self.origin_y, other.origin_y, abs_tol=1e-9)
        )

    __hash__ = None  # mutable-looking value type: equality by content, not hashable

    def __repr__(self) -> str:
        return (
            f"World({self.name!r}, {self.width}x{self.height} cells at {self.resolution} m, "
            f"origin=({self.origin_x}, {self.origin_y}))"
        )
