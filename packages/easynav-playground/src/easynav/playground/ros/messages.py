"""Building the playground's ROS messages from simulator state (the node boundary)."""

from __future__ import annotations

import array
import math

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from sensor_msgs.msg import Imu, LaserScan, NavSatFix

from easynav.playground.sim.laser_scanner import LaserScanner
from easynav.playground.sim.world import World
from easynav.system.ros.converters import time_to_msg


def stamp_msg(seconds: float) -> Time:
    """Simulated seconds as builtin_interfaces/Time."""
    return time_to_msg(seconds)


def laser_scan_msg(
    scanner: LaserScanner, ranges: np.ndarray, stamp: float, frame: str
) -> LaserScan:
    """A LaserScan of ``ranges`` (REP-117 infinities kept) taken at ``stamp``."""
    msg = LaserScan()
    msg.header.stamp = stamp_msg(stamp)
    msg.header.frame_id = frame
    msg.angle_min = float(scanner.angle_min)
    msg.angle_max = float(scanner.angle_max)
    msg.angle_increment = float(scanner.angle_increment)
    msg.time_increment = 0.0
    msg.scan_time = float(scanner.period)
    msg.range_min = float(scanner.min_range)
    msg.range_max = float(scanner.max_range)
    msg.ranges = array.array("f", np.asarray(ranges, dtype=np.float32).tobytes())
    return msg


def planar_odometry_msg(
    stamp: float,
    frame: str,
    child: str,
    pose: tuple[float, float, float],
    twist: tuple[float, float],
    pose_variance: tuple[float, float] = (0.0, 0.0),
) -> Odometry:
    """A nav_msgs/Odometry of a planar pose ``(x, y, yaw)`` and twist ``(v, w)``.

    ``pose_variance`` = (position variance, yaw variance) on the covariance diagonal.
    """
    msg = Odometry()
    msg.header.stamp = stamp_msg(stamp)
    msg.header.frame_id = frame
    msg.child_frame_id = child
    x, y, yaw = pose
    msg.pose.pose.position.x = float(x)
    msg.pose.pose.position.y = float(y)
    msg.pose.pose.orientation.z = math.sin(0.5 * yaw)
    msg.pose.pose.orientation.w = math.cos(0.5 * yaw)
    pos_var, yaw_var = pose_variance
    cov = [0.0] * 36
    cov[0] = cov[7] = float(pos_var)
    cov[35] = float(yaw_var)
    msg.pose.covariance = cov
    msg.twist.twist.linear.x = float(twist[0])
    msg.twist.twist.angular.z = float(twist[1])
    return msg


def planar_transform_msg(
    stamp: float, parent: str, child: str, x: float, y: float, z: float = 0.0, yaw: float = 0.0
) -> TransformStamped:
    """A geometry_msgs/TransformStamped ``parent -> child`` of a planar offset."""
    msg = TransformStamped()
    msg.header.stamp = stamp_msg(stamp)
    msg.header.frame_id = parent
    msg.child_frame_id = child
    msg.transform.translation.x = float(x)
    msg.transform.translation.y = float(y)
    msg.transform.translation.z = float(z)
    msg.transform.rotation.z = math.sin(0.5 * yaw)
    msg.transform.rotation.w = math.cos(0.5 * yaw)
    return msg


def occupancy_grid_msg(world: World, stamp: float, frame: str) -> OccupancyGrid:
    """The world as an OccupancyGrid (100 occupied, 0 free), row-major with y as the row."""
    msg = OccupancyGrid()
    msg.header.stamp = stamp_msg(stamp)
    msg.header.frame_id = frame
    msg.info.map_load_time = stamp_msg(stamp)
    msg.info.resolution = float(world.resolution)
    msg.info.width = world.width
    msg.info.height = world.height
    msg.info.origin.position.x = world.origin_x
    msg.info.origin.position.y = world.origin_y
    msg.info.origin.orientation.w = 1.0
    data = np.where(world.occupied, 100, 0).astype(np.int8)
    msg.data = array.array("b", data.tobytes())
    return msg


def imu_msg(reading, frame: str):
    """A sensor_msgs/Imu of an :class:`~easynav.playground.sim.imu_sensor.ImuReading`
    (orientation: the reported heading; covariances from the declared standard deviations,
    orientation covariance -1 when the heading is off)."""
    msg = Imu()
    msg.header.stamp = stamp_msg(reading.stamp)
    msg.header.frame_id = frame
    msg.orientation.z = math.sin(0.5 * reading.yaw)
    msg.orientation.w = math.cos(0.5 * reading.yaw)
    if reading.yaw_std > 0.0:
        msg.orientation_covariance = [0.0] * 9
        msg.orientation_covariance[0] = msg.orientation_covariance[4] = 1e-4
        msg.orientation_covariance[8] = float(reading.yaw_std**2)
    else:
        msg.orientation_covariance = [-1.0] + [0.0] * 8
    wx, wy, wz = reading.angular_velocity
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = wx, wy, wz
    msg.angular_velocity_covariance = list(np.diag([max(reading.gyro_std, 1e-6) ** 2] * 3)
                                           .ravel())
    ax, ay, az = reading.linear_acceleration
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, az
    msg.linear_acceleration_covariance = list(np.diag([max(reading.accel_std, 1e-6) ** 2] * 3)
                                              .ravel())
    return msg


def nav_sat_fix_msg(fix, frame: str):
    """A sensor_msgs/NavSatFix of a :class:`~easynav.playground.sim.gnss_receiver.GnssFix`
    (diagonal-known covariance from the declared noise; NO_FIX with NaN coordinates in an
    outage)."""
    from sensor_msgs.msg import NavSatStatus

    msg = NavSatFix()
    msg.header.stamp = stamp_msg(fix.stamp)
    msg.header.frame_id = frame
    msg.status.status = NavSatStatus.STATUS_FIX if fix.status >= 0 else NavSatStatus.STATUS_NO_FIX
    msg.status.service = NavSatStatus.SERVICE_GPS
    msg.latitude, msg.longitude, msg.altitude = fix.latitude, fix.longitude, fix.altitude
    variance = float(max(fix.std, 0.01) ** 2)
    msg.position_covariance = [variance, 0.0, 0.0, 0.0, variance, 0.0, 0.0, 0.0, 4 * variance]
    msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    return msg
