"""OccupancyGrid: the native form of nav_msgs/OccupancyGrid."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from easynav.core.types import Header, Pose

#: Cell values of nav_msgs/OccupancyGrid.
FREE = 0
OCCUPIED = 100
UNKNOWN = -1


def _no_cells() -> np.ndarray:
    return np.zeros((0, 0), dtype=np.int8)


@dataclass(slots=True)
class OccupancyGrid:
    """A probabilistic occupancy grid: ``data[row, col]`` int8, 0 free … 100 occupied, -1 unknown.

    ``data`` has shape ``(height, width)``; row ``y`` and column ``x`` hold the cell whose corner
    is ``origin + (x, y) * resolution`` (in the origin's frame; ``origin`` may carry a yaw),
    exactly the row-major order of the message's ``data`` field (index ``y * width + x``).

    Thread contract: a plain value; writers store a new grid instead of changing one in place.
    """

    header: Header = field(default_factory=Header)
    resolution: float = 0.05
    origin: Pose = field(default_factory=Pose)
    data: np.ndarray = field(default_factory=_no_cells)

    @property
    def width(self) -> int:
        """Number of columns (cells along x)."""
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        """Number of rows (cells along y)."""
        return int(self.data.shape[0])
