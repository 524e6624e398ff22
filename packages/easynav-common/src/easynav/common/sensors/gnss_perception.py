"""GNSSPerception: the last fix of one GNSS receiver (sensor_msgs/NavSatFix)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

STATUS_NO_FIX = -1
STATUS_FIX = 0
STATUS_SBAS_FIX = 1
STATUS_GBAS_FIX = 2

COVARIANCE_TYPE_UNKNOWN = 0
COVARIANCE_TYPE_APPROXIMATED = 1
COVARIANCE_TYPE_DIAGONAL_KNOWN = 2
COVARIANCE_TYPE_KNOWN = 3


def _zero33() -> np.ndarray:
    return np.zeros((3, 3))


@dataclass(slots=True)
class GNSSPerception:
    """Latitude and longitude (degrees, + north / + east), altitude (m above the WGS 84 ellipsoid).

    ``status`` and ``service`` are NavSatStatus's (``status`` -1 = no fix); ``position_covariance``
    is 3×3 in ENU (m²) with NavSatFix's ``position_covariance_type``.

    Thread contract: a plain value, replaced (never mutated) by the sensors manager.
    """

    latitude: float = math.nan
    longitude: float = math.nan
    altitude: float = math.nan
    position_covariance: np.ndarray = field(default_factory=_zero33)
    position_covariance_type: int = COVARIANCE_TYPE_UNKNOWN
    status: int = STATUS_NO_FIX
    service: int = 0
    frame_id: str = ""
    stamp: float = 0.0
    valid: bool = True
    new_data: bool = True

    @property
    def has_fix(self) -> bool:
        """True with a fix and finite latitude/longitude (a driver may send NaN without fix)."""
        return (
            self.status >= STATUS_FIX
            and math.isfinite(self.latitude)
            and math.isfinite(self.longitude)
        )
