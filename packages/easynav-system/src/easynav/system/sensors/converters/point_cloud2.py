"""sensor_msgs/PointCloud2 <-> ``(N, 3)`` float64 points, vectorised (no per-point Python)."""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.system.sensors.converters.stamps import seconds_to_stamp
from easynav.system.sensors.errors import PerceptionConversionError

# sensor_msgs/PointField datatypes usable for coordinates.
_FLOAT32 = 7
_FLOAT64 = 8
_FLOAT_SIZES = {_FLOAT32: 4, _FLOAT64: 8}
_DATATYPE_NAMES = {1: "INT8", 2: "UINT8", 3: "INT16", 4: "UINT16", 5: "INT32", 6: "UINT32",
                   7: "FLOAT32", 8: "FLOAT64"}  # fmt: skip


def _xyz_dtype(msg: Any) -> np.dtype:
    fields = {f.name: f for f in msg.fields}
    missing = [axis for axis in "xyz" if axis not in fields]
    if missing:
        present = ", ".join(fields) if fields else "none"
        raise PerceptionConversionError(
            f"PointCloud2 has no field {', '.join(missing)} (fields: {present})"
        )
    point_step = int(msg.point_step)
    endian = ">" if msg.is_bigendian else "<"
    formats = []
    offsets = []
    for axis in "xyz":
        f = fields[axis]
        size = _FLOAT_SIZES.get(f.datatype)
        if size is None:
            name = _DATATYPE_NAMES.get(f.datatype, str(f.datatype))
            raise PerceptionConversionError(
                f"PointCloud2 field '{axis}' has datatype {name}: only FLOAT32 and FLOAT64 "
                "coordinates are supported"
            )
        if f.offset + size > point_step:
            raise PerceptionConversionError(
                f"PointCloud2 field '{axis}' (offset {f.offset}, {size} bytes) does not fit in "
                f"point_step {point_step}"
            )
        formats.append(f"{endian}f{size}")
        offsets.append(int(f.offset))
    return np.dtype(
        {"names": ["x", "y", "z"], "formats": formats, "offsets": offsets, "itemsize": point_step}
    )


def points_from_point_cloud2(msg: Any) -> tuple[np.ndarray, int]:
    """``(points, dropped)``: finite xyz rows as float64 ``(N, 3)``; ``dropped`` NaN/inf rows.

    Handles any field offsets, ``point_step``, row padding (``row_step``), organised clouds
    (``height`` > 1) and either byte order. Raises :class:`PerceptionConversionError` naming what
    is wrong for a malformed cloud (missing or non-float x/y/z, fields beyond ``point_step``,
    ``row_step`` shorter than a row, fewer bytes than the header announces).
    """
    width, height = int(msg.width), int(msg.height)
    n = width * height
    if n == 0:
        return np.empty((0, 3)), 0
    dtype = _xyz_dtype(msg)
    point_step, row_step = int(msg.point_step), int(msg.row_step)
    row_bytes = width * point_step
    if row_step < row_bytes:
        raise PerceptionConversionError(
            f"PointCloud2 row_step {row_step} is shorter than width {width} x point_step "
            f"{point_step} = {row_bytes}"
        )
    data = np.frombuffer(msg.data, dtype=np.uint8)
    needed = (height - 1) * row_step + row_bytes
    if data.shape[0] < needed:
        raise PerceptionConversionError(
            f"PointCloud2 data has {data.shape[0]} bytes, {needed} needed for {width}x{height} "
            f"points of {point_step} bytes (row_step {row_step})"
        )
    if row_step != row_bytes and height > 1:
        # Padded rows: gather the payload of each row into one contiguous buffer.
        data = np.ascontiguousarray(
            np.lib.stride_tricks.as_strided(data, (height, row_bytes), (row_step, 1))
        ).reshape(-1)
    records = np.frombuffer(data, dtype=dtype, count=n)
    # Column by column: contiguous 1-D passes, several times faster than axis reductions on an
    # (N, 3) array.
    x = records["x"].astype(np.float64)
    y = records["y"].astype(np.float64)
    z = records["z"].astype(np.float64)
    if dtype["x"].itemsize == 4 and dtype["y"].itemsize == 4 and dtype["z"].itemsize == 4:
        # A NaN or inf coordinate makes the sum non-finite; float32 values cannot overflow it.
        finite = np.isfinite(x + y + z)
    else:
        finite = np.isfinite(x) & np.isfinite(y) & np.isfinite(z)
    kept = int(np.count_nonzero(finite))
    if kept != n:
        x, y, z = x[finite], y[finite], z[finite]
    points = np.empty((kept, 3), dtype=np.float64)
    points[:, 0] = x
    points[:, 1] = y
    points[:, 2] = z
    return points, n - kept


def point_cloud2_from_points(points: np.ndarray, frame_id: str, stamp: float) -> Any:
    """A dense PointCloud2 (x, y, z FLOAT32 at offsets 0, 4, 8; point_step 12; little endian)."""
    from sensor_msgs.msg import PointCloud2, PointField

    msg = PointCloud2()
    msg.header.frame_id = frame_id
    seconds_to_stamp(stamp, msg.header.stamp)
    msg.height = 1
    msg.width = int(points.shape[0])
    msg.fields = [
        PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="y", offset=4, datatype=PointField.FLOAT32, count=1),
        PointField(name="z", offset=8, datatype=PointField.FLOAT32, count=1),
    ]
    msg.is_bigendian = False
    msg.point_step = 12
    msg.row_step = 12 * msg.width
    msg.is_dense = True
    msg.data = np.ascontiguousarray(points, dtype="<f4").tobytes()
    return msg
