"""The collision checkers' debug markers (the original ControllerMethodBase's)."""

from __future__ import annotations

from typing import Any

import numpy as np

#: How long a marker stays shown (s): the checks run at the RT rate, each replaces the last.
COLLISION_MARKER_LIFETIME = 0.2


def collision_markers(
    frame: str,
    stamp: float,
    lower: tuple[float, float, float],
    upper: tuple[float, float, float],
    points: np.ndarray,
    imminent: bool,
    lifetime: float = COLLISION_MARKER_LIFETIME,
) -> Any:
    """The original ControllerMethodBase's collision markers: a visualization_msgs/MarkerArray
    in ``frame`` (namespace ``collision_zone``) with a DELETEALL (id 0), the box ``lower`` –
    ``upper`` (CUBE, id 1) and the ``points`` (N, 3) in it (SPHERE_LIST of 0.03 m, id 2), red on
    an ``imminent`` collision, green otherwise, alpha 0.25, shown for ``lifetime`` s (0.2). Needs
    visualization_msgs (ImportError otherwise)."""
    from geometry_msgs.msg import Point
    from visualization_msgs.msg import Marker, MarkerArray

    from easynav.system.ros.converters import time_to_msg

    stamp_msg = time_to_msg(stamp)
    colour = (1.0, 0.0, 0.0, 0.25) if imminent else (0.0, 1.0, 0.0, 0.25)
    seconds = divmod(int(lifetime * 1e9), 1_000_000_000)

    def marker(marker_id: int, kind: int, action: int) -> Marker:
        m = Marker()
        m.header.frame_id = frame
        m.header.stamp = stamp_msg
        m.ns = "collision_zone"
        m.id = marker_id
        m.type = kind
        m.action = action
        m.pose.orientation.w = 1.0
        return m

    array = MarkerArray()
    array.markers.append(marker(0, Marker.ARROW, Marker.DELETEALL))
    box = marker(1, Marker.CUBE, Marker.ADD)
    (x0, y0, z0), (x1, y1, z1) = lower, upper
    box.pose.position.x, box.pose.position.y = (x0 + x1) / 2.0, (y0 + y1) / 2.0
    box.pose.position.z = (z0 + z1) / 2.0
    box.scale.x, box.scale.y, box.scale.z = x1 - x0, y1 - y0, max(z1 - z0, 0.0)
    sphere_list = marker(2, Marker.SPHERE_LIST, Marker.ADD)
    sphere_list.scale.x = sphere_list.scale.y = sphere_list.scale.z = 0.03
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    finite = pts[np.all(np.isfinite(pts), axis=1)]
    sphere_list.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in finite]
    for m in (box, sphere_list):
        m.color.r, m.color.g, m.color.b, m.color.a = colour
        m.lifetime.sec, m.lifetime.nanosec = seconds
    array.markers.extend((box, sphere_list))
    return array
