"""ImagePerception: the last image of one camera."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _no_image() -> np.ndarray:
    return np.zeros((0, 0, 1), dtype=np.uint8)


@dataclass(slots=True)
class ImagePerception:
    """``image`` is ``(H, W, C)`` (C = 1 for mono/depth images) in the message's pixel type.

    ``encoding`` is the sensor_msgs/Image encoding (e.g. ``"rgb8"``, ``"bgr8"``, ``"mono16"``,
    ``"32FC1"``); the channel order is the encoding's, not converted. The array is read-only
    (shared by every reader of NavState). ``valid``/``new_data`` as :class:`PointPerception`.

    Thread contract: a plain value, replaced (never mutated) by the sensors manager.
    """

    image: np.ndarray = field(default_factory=_no_image)
    encoding: str = ""
    frame_id: str = ""
    stamp: float = 0.0
    valid: bool = True
    new_data: bool = True

    @property
    def height(self) -> int:
        """Rows."""
        return int(self.image.shape[0])

    @property
    def width(self) -> int:
        """Columns."""
        return int(self.image.shape[1])
