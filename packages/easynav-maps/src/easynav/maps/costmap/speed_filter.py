"""SpeedFilter (easynav_costmap_maps_manager/CostmapMapsManager/SpeedFilter): Nav2-style speed
zones from a mask map (beyond the original)."""

from __future__ import annotations

import math
from typing import Any

from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import ROBOT_POSE
from easynav.core.plugins import Param
from easynav.core.types import Costmap2D
from easynav.core.warning_throttle import WarningThrottle
from easynav.maps.costmap.costmap_filter import CostmapFilter
from easynav.maps.costmap.filter_mask import FilterMask
from easynav.maps.costmap.keepout_filter import load_filter_mask
from easynav.maps.costmap.keys import SPEED_LIMIT

#: ``speed_limit`` outside every speed zone: the robot_limits as they are.
NO_LIMIT = 1.0


def speed_limit_fraction(
    mask_value: int, kind: str, base: float, multiplier: float, max_linear_vel: float
) -> float:
    """The fraction (0, 1] of the robot's limits a mask value allows (Nav2's SpeedFilter rule).

    ``limit = base + multiplier · mask_value``; ``kind`` ``percent``: percent of the maximum
    speed, ``absolute``: m/s (divided by ``max_linear_vel``). A mask value of 0 or -1 (free,
    unknown), a limit ≤ 0 or at/above the maximum, is no limit (1.0).
    """
    if mask_value <= 0:
        return NO_LIMIT
    limit = base + multiplier * mask_value
    if not math.isfinite(limit) or limit <= 0.0:
        return NO_LIMIT
    if kind == "percent":
        fraction = limit / 100.0
    else:
        if not max_linear_vel > 0.0:
            return NO_LIMIT
        fraction = limit / max_linear_vel
    return min(NO_LIMIT, fraction)


class SpeedFilter(CostmapFilter):
    """Writes the speed limit of the zone the robot is in to NavState ``speed_limit``.

    The mask is a map_server map in the map frame (like Nav2's speed masks, ``mode: scale`` to
    keep grey levels): the value ``v`` (0…100) of the mask cell under the robot
    (``robot_pose``) gives ``limit = base + multiplier · v``, a percent of the maximum speed
    (``type: percent``) or m/s (``type: absolute``); 0 or -1 is no zone. ``speed_limit`` is that
    limit as a **fraction** (0, 1] of the limits in force (1.0 outside every zone), for the
    linear and angular speeds alike: controller_node's velocity output cuts the limits it
    enforces by it (controllers keep seeing the limits without the zone). The costmap itself is
    not changed.

    Thread contract: as :class:`CostmapFilter`. ``speed_limit`` is not written while the robot
    pose is unknown. Exceptions: configure fails naming ``mask_path_file`` when the mask is
    missing or malformed.
    """

    PARAMETERS = (
        Param("mask_package", "", "package holding the mask (empty: mask_path_file is a path)"),
        Param("mask_path_file", "", "speed mask map YAML inside mask_package, or a path"),
        Param("type", "percent", "what the limit is: percent of max speed or m/s",
              choices=("percent", "absolute")),
        Param("base", 0.0, "limit = base + multiplier * mask value"),
        Param("multiplier", 1.0, "limit = base + multiplier * mask value"),
        Param("enabled", True, "apply the speed zones (false: speed_limit 1.0)"),
    )
    READS = (ROBOT_POSE,)
    WRITES = (SPEED_LIMIT,)

    def __init__(self) -> None:
        super().__init__()
        self.mask: FilterMask | None = None
        self._throttle = WarningThrottle(period=5.0)

    def on_initialize(self) -> None:
        self.mask = load_filter_mask(self)

    def on_parameter_changed(self, name: str, value: Any) -> None:
        if name in ("mask_package", "mask_path_file"):
            self.mask = load_filter_mask(self)

    def update(self, nav_state: NavState, costmap: Costmap2D) -> None:
        """Write ``speed_limit`` for the robot's position. Non-RT thread."""
        if not self.params.enabled or self.mask is None:
            nav_state.set(SPEED_LIMIT, NO_LIMIT)
            return
        if not nav_state.has(ROBOT_POSE):
            self._throttle.warn(
                self.logger, "no-pose", f"{self.plugin_name}: no robot_pose: speed zone unknown"
            )
            return
        pose = nav_state.get(ROBOT_POSE).pose
        if not (math.isfinite(pose.x) and math.isfinite(pose.y)):
            return
        value = self.mask.value_at(pose.x, pose.y)
        fraction = speed_limit_fraction(
            value, self.params.type, self.params.base, self.params.multiplier,
            self.context.robot_limits().max_linear_vel,
        )
        nav_state.set(SPEED_LIMIT, float(fraction))
