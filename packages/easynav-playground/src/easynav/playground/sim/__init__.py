"""The playground's simulator core: plain numpy, no ROS."""

from easynav.playground.sim.base_limits import BaseLimits
from easynav.playground.sim.box_obstacle import BoxObstacle, rasterize_boxes
from easynav.playground.sim.collision import Collision
from easynav.playground.sim.collision_checker import CollisionChecker
from easynav.playground.sim.diff_drive_robot import DiffDriveRobot, integrate_unicycle
from easynav.playground.sim.fleet import Fleet, PeerRobot
from easynav.playground.sim.gnss_receiver import GnssFix, GnssReceiver
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.sim.imu_sensor import ImuReading, ImuSensor
from easynav.playground.sim.laser_scanner import LaserScanner
from easynav.playground.sim.lidar_3d import Lidar3D
from easynav.playground.sim.moving_obstacle import MovingObstacle
from easynav.playground.sim.multilevel import MultiLevelWorld
from easynav.playground.sim.ray_casting import cast_rays_discs, cast_rays_grid
from easynav.playground.sim.scripted_obstacle import ScriptedObstacle
from easynav.playground.sim.simulation import Simulation
from easynav.playground.sim.terrain import Terrain
from easynav.playground.sim.wheel_odometry import WheelOdometry
from easynav.playground.sim.world import World

__all__ = [
    "BaseLimits",
    "BoxObstacle",
    "Collision",
    "CollisionChecker",
    "DiffDriveRobot",
    "Fleet",
    "GnssFix",
    "GnssReceiver",
    "GroundTruthRecorder",
    "ImuReading",
    "ImuSensor",
    "LaserScanner",
    "Lidar3D",
    "MovingObstacle",
    "MultiLevelWorld",
    "PeerRobot",
    "ScriptedObstacle",
    "Simulation",
    "Terrain",
    "WheelOdometry",
    "World",
    "cast_rays_discs",
    "cast_rays_grid",
    "integrate_unicycle",
    "rasterize_boxes",
]
