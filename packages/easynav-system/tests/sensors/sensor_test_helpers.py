"""Builders of real ROS sensor messages for the sensors tests (independent of the converters)."""

from __future__ import annotations

import math

import numpy as np
from builtin_interfaces.msg import Time


def ros_time(seconds: float) -> Time:
    ns = round(seconds * 1e9)
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def make_scan(ranges, angle_min=-math.pi / 2, angle_increment=None, range_min=0.1,
              range_max=10.0, frame="laser", stamp=0.0):  # fmt: skip
    from sensor_msgs.msg import LaserScan

    ranges = np.asarray(ranges, dtype=np.float32)
    if angle_increment is None:
        angle_increment = math.pi / max(1, len(ranges) - 1)
    msg = LaserScan()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    msg.angle_min = float(angle_min)
    msg.angle_increment = float(angle_increment)
    msg.angle_max = float(angle_min + angle_increment * (len(ranges) - 1))
    msg.range_min = float(range_min)
    msg.range_max = float(range_max)
    msg.ranges = ranges.tolist()
    return msg


def make_cloud(points, frame="lidar", stamp=0.0, dtype="f4", offsets=(0, 4, 8), point_step=None,
               big_endian=False, height=1, row_padding=0, extra_fields=True):  # fmt: skip
    """A PointCloud2 with x, y, z of ``dtype`` at ``offsets`` (plus an 'intensity' field)."""
    from sensor_msgs.msg import PointCloud2, PointField

    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    n = points.shape[0]
    size = np.dtype(dtype).itemsize
    if point_step is None:
        point_step = max(offsets) + size + (4 if extra_fields else 0)
    endian = ">" if big_endian else "<"
    names = ["x", "y", "z"]
    formats = [endian + dtype] * 3
    offs = list(offsets)
    fields = [
        PointField(name=name, offset=o, datatype=7 if size == 4 else 8, count=1)
        for name, o in zip(names, offs, strict=True)
    ]
    if extra_fields:
        names.append("intensity")
        formats.append(endian + "f4")
        offs.append(point_step - 4)
        fields.append(PointField(name="intensity", offset=point_step - 4, datatype=7, count=1))
    record = np.dtype({"names": names, "formats": formats, "offsets": offs,
                       "itemsize": point_step})  # fmt: skip
    arr = np.zeros(n, dtype=record)
    arr["x"], arr["y"], arr["z"] = points[:, 0], points[:, 1], points[:, 2]
    if extra_fields:
        arr["intensity"] = 7.0
    width = n // height
    raw = arr.tobytes()
    row_bytes = width * point_step
    rows = [raw[r * row_bytes:(r + 1) * row_bytes] + b"\xee" * row_padding
            for r in range(height)]  # fmt: skip
    msg = PointCloud2()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    msg.height = height
    msg.width = width
    msg.fields = fields
    msg.is_bigendian = big_endian
    msg.point_step = point_step
    msg.row_step = row_bytes + row_padding
    msg.is_dense = False
    msg.data = b"".join(rows)
    return msg


def make_image(array, encoding, frame="camera", stamp=0.0, big_endian=False, row_padding=0):
    from sensor_msgs.msg import Image

    array = np.asarray(array)
    if array.ndim == 2:
        array = array[:, :, None]
    h, w = array.shape[:2]
    dt = array.dtype.newbyteorder(">" if big_endian else "<") if array.itemsize > 1 else array.dtype
    rows = array.astype(dt).reshape(h, -1).view(np.uint8)
    padded = np.concatenate([rows, np.full((h, row_padding), 0xAB, np.uint8)], axis=1)
    msg = Image()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    msg.height, msg.width = h, w
    msg.encoding = encoding
    msg.is_bigendian = big_endian
    msg.step = padded.shape[1]
    msg.data = padded.tobytes()
    return msg


def make_imu(frame="imu", stamp=0.0, yaw=0.3, gyro=(0.0, 0.0, 0.5), accel=(0.0, 0.0, 9.81),
             orientation_known=True):  # fmt: skip
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    msg.orientation.z, msg.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    msg.orientation_covariance[0] = 0.01 if orientation_known else -1.0
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = gyro
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = accel
    msg.angular_velocity_covariance[8] = 0.02
    return msg


def make_fix(lat=40.28, lon=-3.82, alt=650.0, status=0, frame="gps", stamp=0.0):
    from sensor_msgs.msg import NavSatFix

    msg = NavSatFix()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    msg.latitude, msg.longitude, msg.altitude = lat, lon, alt
    msg.status.status = status
    msg.status.service = 1
    msg.position_covariance = [1.0, 0, 0, 0, 2.0, 0, 0, 0, 4.0]
    msg.position_covariance_type = 2
    return msg


def make_odometry(x=1.0, y=2.0, yaw=0.5, vx=0.3, wz=0.1, frame="odom", child="base_footprint",
                  stamp=0.0):  # fmt: skip
    from nav_msgs.msg import Odometry

    msg = Odometry()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    msg.child_frame_id = child
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    msg.twist.twist.linear.x, msg.twist.twist.angular.z = vx, wz
    return msg


def make_detections(boxes, frame="camera", stamp=0.0):
    """``boxes``: list of (id, [(class_id, score), ...], (x, y, z), (sx, sy, sz))."""
    from vision_msgs.msg import Detection3D, Detection3DArray, ObjectHypothesisWithPose

    msg = Detection3DArray()
    msg.header.frame_id = frame
    msg.header.stamp = ros_time(stamp)
    for det_id, hypotheses, center, size in boxes:
        d = Detection3D()
        d.id = det_id
        for class_id, score in hypotheses:
            h = ObjectHypothesisWithPose()
            h.hypothesis.class_id = class_id
            h.hypothesis.score = score
            d.results.append(h)
        d.bbox.center.position.x, d.bbox.center.position.y, d.bbox.center.position.z = center
        d.bbox.center.orientation.w = 1.0
        d.bbox.size.x, d.bbox.size.y, d.bbox.size.z = size
        msg.detections.append(d)
    return msg
