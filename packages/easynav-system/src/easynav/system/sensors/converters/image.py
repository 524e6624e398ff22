"""sensor_msgs/Image -> ``(H, W, C)`` numpy array in the message's pixel type (zero-copy)."""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from easynav.system.sensors.errors import PerceptionConversionError

# Named encodings of sensor_msgs/image_encodings.hpp: (numpy type, channels).
_NAMED = {
    "rgb8": ("u1", 3), "bgr8": ("u1", 3), "rgba8": ("u1", 4), "bgra8": ("u1", 4),
    "rgb16": ("u2", 3), "bgr16": ("u2", 3), "rgba16": ("u2", 4), "bgra16": ("u2", 4),
    "mono8": ("u1", 1), "mono16": ("u2", 1),
    "bayer_rggb8": ("u1", 1), "bayer_bggr8": ("u1", 1), "bayer_gbrg8": ("u1", 1),
    "bayer_grbg8": ("u1", 1), "bayer_rggb16": ("u2", 1), "bayer_bggr16": ("u2", 1),
    "bayer_gbrg16": ("u2", 1), "bayer_grbg16": ("u2", 1),
    "yuv422": ("u1", 2), "uyvy": ("u1", 2), "yuyv": ("u1", 2), "yuv422_yuy2": ("u1", 2),
}  # fmt: skip
# Generic OpenCV-style encodings: 8UC3, 16UC1, 32FC1, 64FC1, ...
_GENERIC = re.compile(r"^(8|16|32|64)(U|S|F)C([1-9][0-9]*)$")
_GENERIC_TYPES = {
    ("8", "U"): "u1", ("8", "S"): "i1", ("16", "U"): "u2", ("16", "S"): "i2",
    ("32", "S"): "i4", ("32", "F"): "f4", ("64", "F"): "f8",
}  # fmt: skip


def pixel_format(encoding: str) -> tuple[str, int]:
    """``(numpy type code, channels)`` of an image encoding.

    Raises :class:`PerceptionConversionError` for an encoding this converter does not know.
    """
    named = _NAMED.get(encoding)
    if named is not None:
        return named
    m = _GENERIC.match(encoding.upper())
    if m and (m.group(1), m.group(2)) in _GENERIC_TYPES:
        return _GENERIC_TYPES[(m.group(1), m.group(2))], int(m.group(3))
    raise PerceptionConversionError(
        f"Image encoding '{encoding}' is not supported (supported: {', '.join(sorted(_NAMED))}, "
        "and <bits><U|S|F>C<channels> such as 8UC3, 16UC1, 32FC1)"
    )


def image_from_msg(msg: Any) -> np.ndarray:
    """The image as a read-only ``(H, W, C)`` array (a view on the message when possible).

    Raises :class:`PerceptionConversionError` for an unknown encoding, a ``step`` shorter than a
    row or fewer bytes than ``height x step``.
    """
    code, channels = pixel_format(msg.encoding)
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    dtype = np.dtype(code)
    if dtype.itemsize > 1:
        dtype = dtype.newbyteorder(">" if msg.is_bigendian else "<")
    row_bytes = width * channels * dtype.itemsize
    if step < row_bytes:
        raise PerceptionConversionError(
            f"Image step {step} is shorter than a row of {width} x {channels} x "
            f"{dtype.itemsize} bytes = {row_bytes} ('{msg.encoding}')"
        )
    data = np.frombuffer(msg.data, dtype=np.uint8)
    if data.shape[0] < height * step:
        raise PerceptionConversionError(
            f"Image data has {data.shape[0]} bytes, {height * step} needed for {height} rows "
            f"of step {step}"
        )
    rows = data[: height * step].reshape(height, step)[:, :row_bytes]
    if step != row_bytes:
        rows = np.ascontiguousarray(rows)
    image = rows.view(dtype).reshape(height, width, channels)
    if not dtype.isnative:
        image = image.astype(dtype.newbyteorder("="))
    image.flags.writeable = False
    return image
