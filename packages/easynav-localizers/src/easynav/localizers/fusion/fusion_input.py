"""FusionInput: one robot_localization input (``odomN``, ``poseN``, ``twistN``, ``imuN``,
``gpsN``) and its settings."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

#: Input kinds in robot_localization's order, and the message each one carries.
INPUT_KINDS = ("odom", "pose", "twist", "imu", "gps")


def _no_config() -> list[bool]:
    return [False] * 15


@dataclass
class FusionInput:
    """Settings of input ``<kind><index>`` of one filter (robot_localization's names).

    ``config`` (``_config``): which of the 15 state variables the input measures.
    ``differential``: pose values are differentiated into velocities; ``relative``: pose values
    are taken relative to the input's first message; ``pose_use_child_frame`` (``odomN`` only):
    the pose is that of the message's ``child_frame_id``, not of the robot, and is moved to the
    robot frame by the ``child → robot`` transform before anything else. Thresholds are
    Mahalanobis distances (``inf``: no gate): ``pose_threshold`` gates the pose part (an
    IMU's orientation, a GNSS position), ``twist_threshold`` the twist part (an IMU's angular
    velocity), ``acceleration_threshold`` an IMU's linear acceleration.

    Thread contract: a plain value, built at configure time and then only read.
    """

    kind: str
    index: int
    topic: str = ""
    config: list[bool] = field(default_factory=_no_config)
    differential: bool = False
    relative: bool = False
    pose_use_child_frame: bool = False
    queue_size: int = 10
    pose_threshold: float = math.inf
    twist_threshold: float = math.inf
    acceleration_threshold: float = math.inf
    remove_gravitational_acceleration: bool = False

    @property
    def name(self) -> str:
        """``odom0``, ``gps1``..."""
        return f"{self.kind}{self.index}"

    def enabled(self, first: int, last: int) -> list[int]:
        """The configured state indices in ``[first, last]``."""
        return [i for i in range(first, last + 1) if self.config[i]]
