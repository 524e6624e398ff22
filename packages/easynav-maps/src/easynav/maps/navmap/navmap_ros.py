"""ROS messages for a NavMap where ``navmap_ros_interfaces`` is not available.

The original publishes ``navmap_ros_interfaces/NavMap`` and ``NavMapLayer``; that interface
package is not part of this distribution, so the NavMapMapsManager publishes what standard ROS
messages carry: the mesh as a ``visualization_msgs/Marker`` TRIANGLE_LIST (coloured by a cost
layer) and a layer as a ``sensor_msgs/PointCloud2`` of the NavCel centroids with one float32
field named after the layer. ROS imports happen inside the functions.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from easynav.maps.navmap.navmap import LETHAL_OBSTACLE, NO_INFORMATION, NavMap


def cost_colors(values: np.ndarray) -> np.ndarray:
    """(M, 4) float32 RGBA of uint8 costs: free light grey, lethal black, unknown blue-grey,
    costs in between from grey to red."""
    v = np.asarray(values, dtype=np.float64)
    t = np.clip(v / LETHAL_OBSTACLE, 0.0, 1.0)
    rgba = np.column_stack([0.8 + 0.2 * t, 0.8 * (1 - t), 0.8 * (1 - t), np.ones_like(t)])
    rgba[v >= LETHAL_OBSTACLE] = (0.0, 0.0, 0.0, 1.0)
    rgba[v == NO_INFORMATION] = (0.4, 0.45, 0.6, 1.0)
    return rgba.astype(np.float32)


def navmap_to_marker(navmap: NavMap, frame_id: str, stamp: float, layer: str | None = None,
                     namespace: str = "navmap") -> Any:
    """A TRIANGLE_LIST Marker of the mesh; each NavCel coloured by ``layer`` (a uint8 cost
    layer; the first of ``inflated_obstacles``, ``obstacles``, ``occupancy`` present when
    None; uniform grey when none)."""
    from geometry_msgs.msg import Point
    from std_msgs.msg import ColorRGBA
    from visualization_msgs.msg import Marker

    from easynav.core.tf.ros_conversion import seconds_to_stamp

    msg = Marker()
    msg.header.frame_id = frame_id
    seconds_to_stamp(stamp, msg.header.stamp)
    msg.ns = namespace
    msg.id = 0
    msg.type = Marker.TRIANGLE_LIST
    msg.action = Marker.ADD
    msg.pose.orientation.w = 1.0
    msg.scale.x = msg.scale.y = msg.scale.z = 1.0
    msg.color.a = 1.0
    if layer is None:
        layer = next((n for n in ("inflated_obstacles", "obstacles", "occupancy")
                      if navmap.has_layer(n)), None)
    values = navmap.layer(layer) if layer is not None else np.zeros(navmap.num_navcels)
    corners = navmap.vertices[navmap.faces].reshape(-1, 3)
    msg.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in corners]
    colors = [ColorRGBA(r=float(r), g=float(g), b=float(b), a=float(a))
              for r, g, b, a in cost_colors(values)]
    msg.colors = [c for c in colors for _ in range(3)]
    return msg


def layer_to_point_cloud2(navmap: NavMap, layer: str, frame_id: str, stamp: float) -> Any:
    """A PointCloud2 of the NavCel centroids (x, y, z float32) with the values of ``layer`` in a
    float32 field named ``layer`` (offset 12, point_step 16)."""
    from sensor_msgs.msg import PointCloud2, PointField

    from easynav.core.tf.ros_conversion import seconds_to_stamp

    msg = PointCloud2()
    msg.header.frame_id = frame_id
    seconds_to_stamp(stamp, msg.header.stamp)
    msg.height = 1
    msg.width = navmap.num_navcels
    msg.fields = [
        PointField(name=n, offset=4 * k, datatype=PointField.FLOAT32, count=1)
        for k, n in enumerate(("x", "y", "z", layer))
    ]
    msg.is_bigendian = False
    msg.point_step = 16
    msg.row_step = 16 * msg.width
    msg.is_dense = True
    table = np.empty((navmap.num_navcels, 4), dtype="<f4")
    table[:, :3] = navmap.centroids
    table[:, 3] = navmap.layer(layer)
    msg.data = table.tobytes()
    return msg
