"""HeartbeatFields: the contents of one easynav_interfaces/msg/Heartbeat."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class HeartbeatFields:
    """Fields of a Heartbeat message except its header (the node stamps it when publishing).

    ``sequence``: +1 per heartbeat (a gap means lost heartbeats); ``rt_status``: RT_OK,
    RT_LATE or RT_ERROR; ``late_cycles``: late RT cycles since activation; ``safety_mode``;
    ``configuration_hash``: the configuration fingerprint (SHA-256 hex).
    """

    sequence: int
    rt_status: int
    late_cycles: int
    safety_mode: bool
    configuration_hash: str
