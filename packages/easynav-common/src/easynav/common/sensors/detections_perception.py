"""DetectionsPerception: the last detections of one detector (vision_msgs/Detection3DArray)."""

from __future__ import annotations

from dataclasses import dataclass, field

from easynav.common.sensors.detection import Detection


@dataclass(slots=True)
class DetectionsPerception:
    """The detections of one message, in ``frame_id`` at ``stamp``.

    Thread contract: a plain value, replaced (never mutated) by the sensors manager.
    """

    detections: list[Detection] = field(default_factory=list)
    frame_id: str = ""
    stamp: float = 0.0
    valid: bool = True
    new_data: bool = True

    def __len__(self) -> int:
        return len(self.detections)
