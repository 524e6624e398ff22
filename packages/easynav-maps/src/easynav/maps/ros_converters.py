"""Converters between nav_msgs/OccupancyGrid and the native :class:`OccupancyGrid`.

Pure functions, any thread. The cell data travels as an ``array.array('b')`` so that maps of
millions of cells convert without a Python loop.
"""

from __future__ import annotations

import array

import numpy as np
from nav_msgs.msg import OccupancyGrid as OccupancyGridMsg

from easynav.maps.occupancy_grid import OccupancyGrid
from easynav.system.ros.converters import (
    header_from_msg,
    header_to_msg,
    pose_from_msg,
    pose_to_msg,
)


def occupancy_grid_to_msg(grid: OccupancyGrid) -> OccupancyGridMsg:
    """Native grid → nav_msgs/OccupancyGrid (``info.map_load_time`` = the header stamp)."""
    msg = OccupancyGridMsg()
    msg.header = header_to_msg(grid.header)
    msg.info.map_load_time = msg.header.stamp
    msg.info.resolution = float(grid.resolution)
    msg.info.width = grid.width
    msg.info.height = grid.height
    msg.info.origin = pose_to_msg(grid.origin)
    cells = array.array("b")
    cells.frombytes(np.ascontiguousarray(grid.data, dtype=np.int8).tobytes())
    msg.data = cells
    return msg


def occupancy_grid_from_msg(msg: OccupancyGridMsg) -> OccupancyGrid:
    """nav_msgs/OccupancyGrid → native grid.

    Raises :class:`ValueError` when ``data`` does not hold ``width * height`` cells.
    """
    width, height = int(msg.info.width), int(msg.info.height)
    data = np.frombuffer(bytes(memoryview(msg.data)) if len(msg.data) else b"", dtype=np.int8)
    if data.size != width * height:
        raise ValueError(
            f"OccupancyGrid data has {data.size} cells, expected width {width} x height {height}"
            f" = {width * height}"
        )
    return OccupancyGrid(
        header=header_from_msg(msg.header),
        # The field is float32: its shortest decimal form gives back 0.05, not 0.0500000007.
        resolution=float(str(np.float32(msg.info.resolution))),
        origin=pose_from_msg(msg.info.origin),
        data=data.reshape(height, width).copy(),
    )
