"""Header: the stamp and frame of a native message."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(slots=True)
class Header:
    """Stamp (ROS time in seconds, float) and frame id.

    Native types use float seconds for stamps: 64-bit floats keep ~0.25 µs of resolution at
    Unix-epoch magnitudes, far below anything navigation resolves, and make arithmetic trivial.
    Converters turn them into ``builtin_interfaces/Time`` at the node boundary.
    """

    stamp: float = 0.0
    frame_id: str = ""
