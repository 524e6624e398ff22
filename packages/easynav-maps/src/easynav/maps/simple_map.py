"""SimpleMap: the binary occupancy grid of the simple stack, with its ``.map`` text format."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from easynav.core.types import Header, Pose
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.occupancy_grid import FREE, OCCUPIED, OccupancyGrid

#: OccupancyGrid values at or above this are occupied (the original's threshold).
OCCUPIED_THRESHOLD = 50


class SimpleMap:
    """A 2D grid of booleans (True = occupied) with a metric origin and resolution.

    ``cells`` is a ``(height, width)`` bool array indexed ``cells[y, x]``; cell ``(x, y)`` covers
    ``[origin_x + x·res, origin_x + (x+1)·res) × [origin_y + y·res, origin_y + (y+1)·res)`` and
    its centre is ``origin + (i + 0.5)·res``. The origin is the corner of cell (0, 0); the map
    has no rotation. Coordinates may be negative (any origin).

    The ``.map`` text format (the original EasyNav's): line 1 is
    ``width height resolution origin_x origin_y``; line 2 holds ``width*height`` values 0/1,
    row-major with y as the row (index ``y*width + x``).

    World↔cell conversions are vectorised: they accept scalars or numpy arrays.

    Thread contract: a plain value. Writers (maps managers) build a new map and store it in
    NavState instead of changing a stored one, so any thread may read a map it got from NavState.
    Mutating methods (:meth:`mark_occupied`, :meth:`fill`) are for maps the caller owns.
    """

    __slots__ = ("cells", "resolution", "origin_x", "origin_y")

    def __init__(
        self,
        width: int,
        height: int,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        cells: np.ndarray | None = None,
    ) -> None:
        """A ``width × height`` map, all free unless ``cells`` (``(height, width)``) is given.

        Raises :class:`ValueError` naming the bad argument (negative size, resolution not finite
        and > 0, non-finite origin, ``cells`` of another shape).
        """
        width, height = int(width), int(height)
        if width < 0 or height < 0:
            raise ValueError(f"SimpleMap size {width}x{height}: width and height must be >= 0")
        resolution = float(resolution)
        if not math.isfinite(resolution) or resolution <= 0.0:
            raise ValueError(f"SimpleMap resolution {resolution} must be finite and > 0")
        if not (math.isfinite(origin_x) and math.isfinite(origin_y)):
            raise ValueError(f"SimpleMap origin ({origin_x}, {origin_y}) must be finite")
        if cells is None:
            cells = np.zeros((height, width), dtype=bool)
        else:
            cells = np.asarray(cells)
            if cells.shape != (height, width):
                raise ValueError(
                    f"SimpleMap cells have shape {cells.shape}, expected (height, width) = "
                    f"({height}, {width})"
                )
            cells = cells.astype(bool, copy=True)
        self.cells: np.ndarray = cells
        self.resolution = resolution
        self.origin_x = float(origin_x)
        self.origin_y = float(origin_y)

    # -- shape ---------------------------------------------------------------------------------
    @property
    def width(self) -> int:
        """Number of cells along x (columns)."""
        return int(self.cells.shape[1])

    @property
    def height(self) -> int:
        """Number of cells along y (rows)."""
        return int(self.cells.shape[0])

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(min_x, min_y, max_x, max_y)`` of the area covered, in metres."""
        return (
            self.origin_x,
            self.origin_y,
            self.origin_x + self.width * self.resolution,
            self.origin_y + self.height * self.resolution,
        )

    def __repr__(self) -> str:
        return (
            f"SimpleMap({self.width}x{self.height} at {self.resolution:g} m, origin "
            f"({self.origin_x:g}, {self.origin_y:g}), {int(self.cells.sum())} occupied)"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SimpleMap):
            return NotImplemented
        return (
            self.resolution == other.resolution
            and self.origin_x == other.origin_x
            and self.origin_y == other.origin_y
            and self.cells.shape == other.cells.shape
            and bool(np.array_equal(self.cells, other.cells))
        )

    __hash__ = None  # mutable value

    def copy(self) -> SimpleMap:
        """A deep copy."""
        return SimpleMap(
            self.width, self.height, self.resolution, self.origin_x, self.origin_y, self.cells
        )

    def fill(self, occupied: bool) -> None:
        """Set every cell to ``occupied``."""
        self.cells[:, :] = bool(occupied)

    # -- conversions -----------------------------------------------------------------------------
    def world_to_cell(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Cell indices ``(ix, iy)`` (int64, floor) of world points; not bounds-checked."""
        ix = np.floor((np.asarray(x, dtype=float) - self.origin_x) / self.resolution)
        iy = np.floor((np.asarray(y, dtype=float) - self.origin_y) / self.resolution)
        return ix.astype(np.int64), iy.astype(np.int64)

    def cell_to_world(self, ix, iy) -> tuple[np.ndarray, np.ndarray]:
        """World coordinates of cell centres: ``origin + (i + 0.5)·res``."""
        x = self.origin_x + (np.asarray(ix, dtype=float) + 0.5) * self.resolution
        y = self.origin_y + (np.asarray(iy, dtype=float) + 0.5) * self.resolution
        return x, y

    def cells_in_bounds(self, ix, iy) -> np.ndarray:
        """True where the cell indices are inside the map."""
        ix, iy = np.asarray(ix), np.asarray(iy)
        return (ix >= 0) & (iy >= 0) & (ix < self.width) & (iy < self.height)

    def contains(self, x, y) -> np.ndarray:
        """True where world points fall inside the map."""
        return self.cells_in_bounds(*self.world_to_cell(x, y))

    def occupied_at(self, x, y, outside: bool = False) -> np.ndarray:
        """Occupancy of the cells under world points; ``outside`` for points off the map."""
        ix, iy = self.world_to_cell(x, y)
        inside = self.cells_in_bounds(ix, iy)
        result = np.full(np.shape(inside), bool(outside))
        result[inside] = self.cells[iy[inside], ix[inside]]
        return result

    def mark_occupied(self, x, y) -> int:
        """Mark the cells under world points occupied; returns how many points were on the map.

        Points off the map are ignored (a map does not grow); the count lets callers tell.
        """
        ix, iy = self.world_to_cell(x, y)
        inside = self.cells_in_bounds(ix, iy)
        self.cells[iy[inside], ix[inside]] = True
        return int(np.count_nonzero(inside))

    # -- downsampling ----------------------------------------------------------------------------
    def downsample_factor(self, factor: int) -> SimpleMap:
        """A coarser map: each cell covers ``factor × factor`` cells, occupied if any of them is.

        Unlike the original (which dropped the partial blocks at the far edges), partial blocks
        are kept, so the coarse map covers the whole fine map; the cells they lack count as free.
        ``factor`` 1 returns a copy. Raises :class:`ValueError` for ``factor < 1``.
        """
        factor = int(factor)
        if factor < 1:
            raise ValueError(f"downsampling factor {factor} must be >= 1")
        if factor == 1:
            return self.copy()
        new_w = -(-self.width // factor)
        new_h = -(-self.height // factor)
        padded = np.zeros((new_h * factor, new_w * factor), dtype=bool)
        padded[: self.height, : self.width] = self.cells
        coarse = padded.reshape(new_h, factor, new_w, factor).any(axis=(1, 3))
        return SimpleMap(
            new_w, new_h, self.resolution * factor, self.origin_x, self.origin_y, coarse
        )

    def downsample(self, new_resolution: float) -> SimpleMap:
        """A coarser map with cells of ``floor(new_resolution / resolution)`` fine cells.

        The resulting resolution is that integer multiple of the current one (equal to
        ``new_resolution`` when it is a multiple). A ``new_resolution`` not above the current one
        returns a copy. Raises :class:`ValueError` for a non-finite or non-positive value.
        """
        new_resolution = float(new_resolution)
        if not math.isfinite(new_resolution) or new_resolution <= 0.0:
            raise ValueError(f"downsample resolution {new_resolution} must be finite and > 0")
        # The epsilon keeps 0.2 / 0.05 (3.9999999999999996 in floating point) a factor of 4.
        factor = max(1, int(math.floor(new_resolution / self.resolution + 1e-9)))
        return self.downsample_factor(factor)

    # -- occupancy grids -------------------------------------------------------------------------
    @classmethod
    def from_occupancy_grid(
        cls, grid: OccupancyGrid, unknown_as_occupied: bool = True
    ) -> SimpleMap:
        """A binary map from an occupancy grid: values >= 50 occupied, 0…49 free.

        Unknown cells (-1) are occupied by default, so planners never route through space nobody
        has seen (the original made them free: pass ``unknown_as_occupied=False`` for that).
        Raises :class:`ValueError` for a rotated origin (a SimpleMap has no rotation) or values
        outside -1…100 (naming the first bad cell).
        """
        origin = grid.origin
        if abs(origin.yaw) > 1e-9 or abs(origin.qx) > 1e-9 or abs(origin.qy) > 1e-9:
            raise ValueError(
                f"occupancy grid origin is rotated (yaw {origin.yaw:.6f} rad): a SimpleMap "
                f"cannot represent a rotated grid"
            )
        data = np.asarray(grid.data)
        if data.ndim != 2:
            raise ValueError(f"occupancy grid data must be 2D (height, width), got {data.shape}")
        bad = (data < -1) | (data > OCCUPIED)
        if bad.any():
            y, x = (int(v[0]) for v in np.nonzero(bad))
            raise ValueError(
                f"occupancy grid cell (x={x}, y={y}) holds {int(data[y, x])}: values must be "
                f"-1 (unknown) or 0..100"
            )
        cells = data >= OCCUPIED_THRESHOLD
        if unknown_as_occupied:
            cells |= data < 0
        height, width = data.shape
        return cls(width, height, grid.resolution, origin.x, origin.y, cells)

    def to_occupancy_grid(self, frame_id: str = "map", stamp: float = 0.0) -> OccupancyGrid:
        """The map as an occupancy grid: occupied 100, free 0 (no unknown cells)."""
        data = np.where(self.cells, np.int8(OCCUPIED), np.int8(FREE)).astype(np.int8)
        return OccupancyGrid(
            header=Header(stamp=stamp, frame_id=frame_id),
            resolution=self.resolution,
            origin=Pose(self.origin_x, self.origin_y, 0.0),
            data=data,
        )

    @classmethod
    def from_map_yaml(cls, path: str | os.PathLike, unknown_as_occupied: bool = True) -> SimpleMap:
        """Load a ROS map_server map (YAML + image); see :func:`easynav.maps.load_map_yaml`."""
        from easynav.maps.map_yaml import load_map_yaml

        grid = load_map_yaml(path)
        try:
            return cls.from_occupancy_grid(grid, unknown_as_occupied)
        except ValueError as exc:  # e.g. a rotated origin
            raise MapFormatError(f"{path}: {exc}") from None

    # -- the .map text format --------------------------------------------------------------------
    @classmethod
    def load(cls, path: str | os.PathLike) -> SimpleMap:
        """Read a ``.map`` file, or a ROS map YAML (``.yaml``/``.yml``, see :meth:`from_map_yaml`).

        Raises :class:`FileNotFoundError` naming a missing file and :class:`MapFormatError`
        naming the file and line (or YAML key) of a malformed one.
        """
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"map file not found: {path}")
        if path.suffix.lower() in (".yaml", ".yml"):
            return cls.from_map_yaml(path)
        try:
            text = path.read_text(encoding="ascii")
        except UnicodeDecodeError as exc:
            raise MapFormatError(f"{path}: not a .map text file ({exc})") from None
        return cls.parse(text, str(path))

    @classmethod
    def parse(cls, text: str, source: str = "<string>") -> SimpleMap:
        """Parse the ``.map`` format from a string; ``source`` names it in errors."""
        lines = text.splitlines()
        while lines and not lines[-1].strip():
            lines.pop()
        if len(lines) < 2:
            raise MapFormatError(
                f"{source}: a .map file has 2 lines (header, then cell values), found {len(lines)}"
            )
        for number, line in enumerate(lines[2:], start=3):
            if line.strip():
                raise MapFormatError(f"{source}:{number}: unexpected content after the cells")
        header = lines[0].split()
        if len(header) != 5:
            raise MapFormatError(
                f"{source}:1: expected 'width height resolution origin_x origin_y', got "
                f"{lines[0].strip()!r}"
            )
        try:
            width, height = int(header[0]), int(header[1])
        except ValueError:
            raise MapFormatError(
                f"{source}:1: width and height must be integers, got {header[0]!r} {header[1]!r}"
            ) from None
        try:
            resolution, origin_x, origin_y = (float(v) for v in header[2:])
        except ValueError:
            raise MapFormatError(
                f"{source}:1: resolution and origin must be numbers, got {' '.join(header[2:])!r}"
            ) from None
        if width < 0 or height < 0:
            raise MapFormatError(f"{source}:1: width {width} and height {height} must be >= 0")
        if not math.isfinite(resolution) or resolution <= 0.0:
            raise MapFormatError(f"{source}:1: resolution {resolution} must be finite and > 0")
        if not (math.isfinite(origin_x) and math.isfinite(origin_y)):
            raise MapFormatError(f"{source}:1: origin ({origin_x}, {origin_y}) must be finite")
        tokens = np.array(lines[1].split())
        expected = width * height
        if tokens.size != expected:
            raise MapFormatError(
                f"{source}:2: expected {expected} cell values (width {width} x height {height}), "
                f"found {tokens.size}"
            )
        occupied = tokens == "1"
        bad = ~(occupied | (tokens == "0"))
        if bad.any():
            index = int(np.argmax(bad))
            raise MapFormatError(
                f"{source}:2: cell value {str(tokens[index])!r} at index {index} "
                f"(x={index % max(width, 1)}, y={index // max(width, 1)}) is not 0 or 1"
            )
        return cls(width, height, resolution, origin_x, origin_y, occupied.reshape(height, width))

    def to_text(self) -> str:
        """The map in the ``.map`` format (two lines, ending with a newline)."""
        header = (
            f"{self.width} {self.height} {self.resolution!r} {self.origin_x!r} {self.origin_y!r}"
        )
        flat = self.cells.ravel()
        if flat.size == 0:
            return header + "\n\n"
        # One byte per digit with a space between: fast for maps of millions of cells.
        chars = np.full(2 * flat.size - 1, ord(" "), dtype=np.uint8)
        chars[::2] = flat.astype(np.uint8) + ord("0")
        return header + "\n" + chars.tobytes().decode("ascii") + "\n"

    def save(self, path: str | os.PathLike) -> None:
        """Write the map as a ``.map`` file (round-trips exactly through :meth:`load`).

        Raises :class:`OSError` (naming the file) when it cannot be written.
        """
        path = Path(path)
        try:
            path.write_text(self.to_text(), encoding="ascii")
        except OSError as exc:
            raise OSError(f"cannot write map file {path}: {exc.strerror or exc}") from exc
