"""vision_msgs/Detection3DArray -> list of Detection."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from easynav.common.sensors.detection import Detection
from easynav.core.types import Pose


def detections_from_msg(msg: Any) -> tuple[list[Detection], list[str]]:
    """``(detections, problems)``: one Detection per Detection3D with a finite bounding box.

    A detection whose box centre or size is not finite is left out and described in
    ``problems`` (the caller warns, naming the sensor).
    """
    detections: list[Detection] = []
    problems: list[str] = []
    for i, d in enumerate(msg.detections):
        c = d.bbox.center
        s = d.bbox.size
        values = (
            c.position.x, c.position.y, c.position.z,
            c.orientation.x, c.orientation.y, c.orientation.z, c.orientation.w,
            s.x, s.y, s.z,
        )  # fmt: skip
        if not all(math.isfinite(v) for v in values):
            problems.append(f"detection {i} (id '{d.id}') has a non-finite bounding box {values}")
            continue
        class_id, score = "", 0.0
        if d.results:
            best = max(d.results, key=lambda r: r.hypothesis.score)
            class_id, score = best.hypothesis.class_id, float(best.hypothesis.score)
        detections.append(
            Detection(
                class_id=class_id,
                score=score,
                center=Pose(*values[:7]),
                size=np.array(values[7:]),
                id=d.id,
            )
        )
    return detections, problems
