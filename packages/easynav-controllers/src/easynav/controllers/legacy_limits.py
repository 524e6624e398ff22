"""The original's per-controller limits as deprecated caps on the limits in force."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace

from easynav.core.robot import RobotLimits

#: How a deprecated cap combines with the field of :class:`RobotLimits` it cuts down.
#: ``max``: the field becomes min(field, cap); ``min``: max(field, cap) (a negative bound);
#: ``neg``: the cap is a negative bound of a symmetric field: field = min(field, -cap).
#: ``min_neg``: the cap is a magnitude that bounds a negative field: field = max(field, -cap).
CAP_KINDS = ("max", "min", "neg", "min_neg")


def capped_limits(
    limits: RobotLimits, caps: Sequence[tuple[str, str, str]], values: Mapping[str, float]
) -> RobotLimits:
    """``limits`` cut down by the deprecated parameters that are set (not NaN).

    ``caps`` lists ``(parameter, RobotLimits field, kind)`` (kind in :data:`CAP_KINDS`; one
    parameter may cap several fields);
    ``values`` holds the parameter values (``self.params``). A cap never raises a limit: the
    limits in force (``controller_node.robot_limits``, cut down by a slow-down mitigation or a
    speed zone) always win when tighter. Pure function, any thread.
    """
    changes: dict[str, float] = {}
    for name, field_name, kind in caps:
        cap = values[name]
        if math.isnan(cap):
            continue
        current = changes.get(field_name, getattr(limits, field_name))
        if kind == "max":
            changes[field_name] = min(current, cap)
        elif kind == "min":
            changes[field_name] = max(current, cap)
        elif kind == "min_neg":
            changes[field_name] = max(current, -cap)
        else:
            changes[field_name] = min(current, -cap)
    return replace(limits, **changes) if changes else limits


def warn_set_caps(
    caps: Sequence[tuple[str, str, str]], values: Mapping[str, float], plugin: str, warn
) -> None:
    """One deprecation warning per deprecated limit parameter and field it caps, when set."""
    for name, field_name, _kind in caps:
        if not math.isnan(values[name]):
            warn(
                f"{plugin}.{name} is deprecated: set controller_node.robot_limits.{field_name} "
                f"(it still caps the limit at {values[name]:g})"
            )
