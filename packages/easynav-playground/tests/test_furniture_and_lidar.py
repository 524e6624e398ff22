"""Furniture with heights and the 3D lidar, without ROS (issue #16)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.playground.sim import (
    BaseLimits,
    BoxObstacle,
    DiffDriveRobot,
    LaserScanner,
    Lidar3D,
    Simulation,
    WheelOdometry,
    World,
    rasterize_boxes,
)
from easynav.playground.world_description import WorldDescription

SHELF = BoxObstacle("low shelf", 2.0, -0.5, 2.4, 0.5, 0.3, 0.4)
TABLE_TOP = BoxObstacle("table top", 4.0, -0.5, 5.0, 0.5, 0.7, 0.75)
LEG = BoxObstacle("leg", 4.0, -0.5, 4.05, -0.45, 0.0, 0.7)


def empty_world(size=8.0):
    return World(np.zeros((int(size / 0.05), int(size / 0.05)), dtype=bool), 0.05, -1.0, -4.0)


def simulation(boxes, lidar=None, x=0.0):
    world = empty_world()
    return Simulation(
        world,
        DiffDriveRobot(x, 0.0, 0.0, limits=BaseLimits()),
        LaserScanner(beams=360, range_noise_std=0.0, rng=np.random.default_rng(0)),
        WheelOdometry(rng=np.random.default_rng(1)),
        robot_radius=0.2,
        boxes=boxes,
        robot_height=0.5,
        laser_height=0.25,
        lidar=lidar,
        lidar_offset=(0.0, 0.0, 0.45, 0.0),
    )


def test_the_laser_misses_the_low_shelf_and_the_table_top_but_sees_the_leg():
    sim = simulation([SHELF, TABLE_TOP, LEG])
    ranges = sim.scan_now()
    ahead = int(np.argmin(np.abs(sim.scanner.angles)))
    assert not math.isfinite(ranges[ahead]) or ranges[ahead] > 5.0  # under shelf and table top
    laser_x = sim.laser_pose()[0]
    to_leg = math.atan2(-0.475, 4.025 - laser_x)
    beam = int(np.argmin(np.abs(sim.scanner.angles - to_leg)))
    assert ranges[beam] == pytest.approx(math.hypot(4.0 - laser_x, 0.475), abs=0.1)


def test_the_robot_hits_the_shelf_and_passes_under_the_table():
    sim = simulation([SHELF, TABLE_TOP, LEG])
    assert sim.checker.colliding_with(2.2, 0.0) == "wall"  # the shelf reaches below 0.5 m
    assert sim.checker.colliding_with(4.5, 0.0) is None  # under the table top
    assert sim.checker.colliding_with(4.1, -0.4) == "wall"  # a leg
    assert rasterize_boxes(sim.world, [TABLE_TOP], 0.0, 0.5) is sim.world


def test_the_lidar_sees_the_shelf_the_table_top_and_the_floor():
    lidar = Lidar3D(rings=16, beams=360, max_range=8.0, noise_std=0.0,
                    rng=np.random.default_rng(2))
    sim = simulation([SHELF, TABLE_TOP], lidar=lidar)
    points = sim.cloud_now()  # lidar frame: at (0, 0, 0.45)
    world_z = points[:, 2] + 0.45
    on_shelf = (
        (points[:, 0] >= 1.99) & (points[:, 0] <= 2.41) & (np.abs(points[:, 1]) <= 0.5)
        & (world_z > 0.1)  # not the floor seen under the shelf
    )
    assert on_shelf.any()
    assert ((world_z[on_shelf] >= 0.3 - 1e-6) & (world_z[on_shelf] <= 0.4 + 1e-6)).all()
    on_top = (points[:, 0] >= 3.99) & (world_z >= 0.7 - 1e-6) & (world_z <= 0.75 + 1e-6)
    assert on_top.any()
    assert (np.abs(world_z) < 1e-6).any()  # the floor
    assert np.linalg.norm(points, axis=1).max() <= 8.0 + 1e-9


def test_lidar_clouds_arrive_at_the_lidar_rate():
    lidar = Lidar3D(rings=4, beams=36, rate=5.0, noise_std=0.0)
    sim = simulation([], lidar=lidar)
    stamps = []
    sim.on_cloud.append(lambda stamp, points: stamps.append(stamp))
    sim.run_for(1.0)
    assert len(stamps) == 5


def test_bad_boxes_and_lidars_name_the_culprit():
    with pytest.raises(ValueError, match="furniture\\[0\\]"):
        BoxObstacle.from_dict({"box": [1, 1, 0, 0], "z": [0, 1]}, "w.yaml: furniture[0]")
    with pytest.raises(ValueError, match="rings"):
        Lidar3D(rings=0)


def test_the_furnished_office_world_loads_with_its_robot():
    description = WorldDescription.resolve("furnished_office")
    names = [b.name for b in description.furniture]
    assert "low shelf" in names and "table top" in names
    shelf = description.furniture[names.index("low shelf")]
    assert shelf.z0 > 0.25 and shelf.z1 < 0.5  # above the laser, below the robot's top
    defaults = description.robot.parameter_defaults()
    assert defaults["robot_height"] == 0.5 and defaults["lidar.enabled"] is True
