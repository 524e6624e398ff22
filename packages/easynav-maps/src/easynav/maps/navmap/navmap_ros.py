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

from easynav.maps.navmap.cdr import CdrBuffer
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


def navmap_marker_cdr(navmap: NavMap, frame_id: str, stamp: float, layer: str | None = None,
                      namespace: str = "navmap") -> bytes:
    """The CDR serialisation of a ``visualization_msgs/Marker`` TRIANGLE_LIST of the mesh, ready
    for ``Publisher.publish`` (rclpy publishes bytes as they are): each NavCel coloured by
    ``layer`` (a uint8 cost layer; the first of ``inflated_obstacles``, ``obstacles``,
    ``occupancy`` present when None; uniform grey when none).

    Written with numpy, not through a million ``Point`` objects: 295k NavCels take well under a
    second instead of 16 s (rclpy message construction)."""
    if layer is None:
        layer = next((n for n in ("inflated_obstacles", "obstacles", "occupancy")
                      if navmap.has_layer(n)), None)
    values = navmap.layer(layer) if layer is not None else np.zeros(navmap.num_navcels)
    sec = int(np.floor(stamp))
    buf = CdrBuffer()
    buf.write("i", sec)  # header
    buf.write("I", min(int(round((stamp - sec) * 1e9)), 999_999_999))
    buf.write_string(frame_id)
    buf.write_string(namespace)
    buf.write("i", 0)  # id
    buf.write("i", 11)  # type TRIANGLE_LIST
    buf.write("i", 0)  # action ADD
    for value in (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0):  # pose, scale
        buf.write("d", value)
    for value in (1.0, 1.0, 1.0, 1.0):  # color
        buf.write("f", value)
    buf.write("i", 0)  # lifetime
    buf.write("I", 0)
    buf.write("?", False)  # frame_locked
    buf.write_array(navmap.vertices[navmap.faces].reshape(-1, 3), np.float64)  # points
    buf.write_array(np.repeat(cost_colors(values), 3, axis=0), np.float32)  # colors
    buf.write_string("")  # texture_resource
    buf.write("i", 0)  # texture: header, format, data
    buf.write("I", 0)
    buf.write_string("")
    buf.write_string("")
    buf.write_array([], np.uint8)
    buf.write("I", 0)  # uv_coordinates
    buf.write_string("")  # text
    buf.write_string("")  # mesh_resource
    buf.write_string("")  # mesh_file: filename, data
    buf.write_array([], np.uint8)
    buf.write("?", False)  # mesh_use_embedded_materials
    return buf.getvalue()


def navmap_to_marker(navmap: NavMap, frame_id: str, stamp: float, layer: str | None = None,
                     namespace: str = "navmap") -> Any:
    """:func:`navmap_marker_cdr` as a ``visualization_msgs/Marker`` message object."""
    from rclpy.serialization import deserialize_message
    from visualization_msgs.msg import Marker

    return deserialize_message(navmap_marker_cdr(navmap, frame_id, stamp, layer, namespace),
                               Marker)


def layer_to_point_cloud2(navmap: NavMap, layer: str, frame_id: str, stamp: float) -> Any:
    """A PointCloud2 of the NavCel centroids (x, y, z float32) with the values of ``layer`` in a
    float32 field named ``layer`` (offset 12, point_step 16)."""
    from sensor_msgs.msg import PointCloud2, PointField

    from easynav.system.tf.ros_conversion import seconds_to_stamp

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
