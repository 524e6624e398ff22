"""The costmap AMCL without ROS: tracking a known trajectory, relocalising from a wrong
initial pose (global localisation, kidnapping), KLD sizes, parameters."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import DictParameters, PluginConfigurationError, PluginContext
from easynav.core.types import Costmap2D, Header, Odometry, Pose, Transform, TransformStamped
from easynav.localizers.costmap_amcl_localizer import CostmapAMCLLocalizer
from easynav.localizers.costmap_sampling import (
    RESET_FINE_SIGMA,
    RESET_STRIDE,
    beam_likelihood_field,
    kld_particle_count,
    sample_free_space,
    sensor_reset_poses,
)
from easynav.localizers.particle_filter import likelihood_field
from easynav.maps import SimpleMap, resolve_map_file

_namespaces = itertools.count()


def house_costmap() -> Costmap2D:
    """The shipped house map as a costmap: walls lethal (254), the rest free."""
    world = SimpleMap.load(resolve_map_file("easynav_maps", "worlds/home.map"))
    data = np.where(world.cells, 254, 0).astype(np.uint8)
    return Costmap2D(data, world.resolution, world.origin_x, world.origin_y, "map", 1.0)


def ray_cast(costmap: Costmap2D, pose, beams: int, max_range: float, rng, noise=0.01):
    """Points (laser frame, z 0) of a 360° laser at ``pose``; beams without a wall are lost."""
    angles = np.linspace(-math.pi, math.pi, beams, endpoint=False)
    r = np.arange(0.0, max_range, costmap.resolution / 2)
    a = angles[:, None] + pose[2]
    costs = costmap.cost_at(pose[0] + r * np.cos(a), pose[1] + r * np.sin(a), outside=0)
    occupied = costs == 254
    hit = occupied.any(axis=1)
    ranges = r[occupied.argmax(axis=1)][hit] + rng.normal(0.0, noise, hit.sum())
    return np.column_stack(
        (ranges * np.cos(angles[hit]), ranges * np.sin(angles[hit]), np.zeros(hit.sum()))
    )


class Sim:
    """A unicycle on a costmap (the house's by default) with drifting odometry, a 0.25 m high
    laser, a clock."""

    def __init__(self, params: dict, start=(0.0, 0.0, 0.0), seed=0, costmap=None,
                 laser_range=6.0) -> None:
        self.rng = np.random.default_rng(seed)
        self.costmap = house_costmap() if costmap is None else costmap
        self.laser_range = laser_range
        self.range_noise = 0.01  # m (σ)
        self.t = 10.0
        self.true = np.array(start, dtype=float)
        self.odom = np.zeros(3)
        namespace = f"costmap_amcl_test_{next(_namespaces)}"
        self.buffer = get_tf_buffer(namespace)
        self.buffer.set_transform(
            TransformStamped(Header(0.0, "base_footprint"), "base_laser",
                             Transform(np.array([0.1, 0.0, 0.25]))),
            "test",
            is_static=True,
        )
        context = PluginContext(
            parameters=DictParameters({f"amcl.{k}": v for k, v in params.items()}),
            namespace=namespace,
            now=lambda: self.t,
        )
        self.amcl = CostmapAMCLLocalizer()
        self.amcl.initialize(context, "amcl")
        # A seeded generator, and the initial cloud drawn again with it: the run is repeatable.
        self.amcl.filter.rng = np.random.default_rng(seed + 100)
        p = self.amcl.params
        self.amcl.filter.seed(
            p["initial_pose.x"], p["initial_pose.y"], p["initial_pose.yaw"],
            np.eye(2) * p["initial_pose.std_dev_xy"] ** 2, p["initial_pose.std_dev_yaw"],
        )
        self.nav_state = NavState()
        self.nav_state.set("map.base", self.costmap)

    def step(self, v: float, w: float, dt: float, correct: bool) -> None:
        yaw = self.true[2]
        self.true += (v * math.cos(yaw) * dt, v * math.sin(yaw) * dt, w * dt)
        oyaw = self.odom[2]  # odometry drifts 2 % in distance and 3 % in rotation
        self.odom += (1.02 * v * math.cos(oyaw) * dt, 1.02 * v * math.sin(oyaw) * dt,
                      1.03 * w * dt)
        self.t += dt
        self.amcl.set_odometry(
            Odometry(Header(self.t, "odom"), "base_footprint", Pose.from_xy_yaw(*self.odom))
        )
        self.amcl.update_rt(self.nav_state)
        if correct:
            c, s = math.cos(self.true[2]), math.sin(self.true[2])
            laser = (self.true[0] + 0.1 * c, self.true[1] + 0.1 * s, self.true[2])
            points = ray_cast(self.costmap, laser, 180, self.laser_range, self.rng,
                              self.range_noise)
            self.nav_state.set("laser1", PointPerception(points, "base_laser", self.t))
            self.amcl.update(self.nav_state)

    def error(self) -> float:
        pose = self.nav_state.get("robot_pose", Odometry).pose
        return math.hypot(pose.x - self.true[0], pose.y - self.true[1])

    def drive(self, seconds: float, v=0.3, dt=0.02) -> list[float]:
        errors = []
        for i in range(int(seconds / dt)):
            self.step(v, 0.3 * math.sin(self.t * 0.8), dt, correct=(i % 10 == 0))
            errors.append(self.error())
        return errors


BASE = {
    "rt_freq": 50.0,
    "freq": 5.0,
    "noise_translation": 0.05,
    "noise_rotation": 0.1,
    "noise_translation_to_rotation": 0.1,
    "num_particles": 300,
}


@pytest.mark.parametrize("model", ["hit_count", "likelihood_field"])
def test_tracks_a_known_trajectory(model):
    params = dict(BASE, sensor_model=model, **{
        "initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=1)
    errors = sim.drive(12.0)
    assert max(errors[100:]) < 0.15, errors[::50]
    assert np.mean(errors[-200:]) < 0.08
    trace = sim.nav_state.get("localizer.amcl.covariance_trace", float)
    assert 0.0 < trace < 0.05


def test_relocalises_from_a_wrong_initial_pose_by_global_localisation():
    # The belief starts 1.5 m and 1 rad away, confident; a global localisation is asked
    # through NavState (as a recovery would).
    params = dict(BASE, sensor_model="likelihood_field", kld_sampling=True, min_particles=300,
                  max_particles=20000, **{"initial_pose.x": 1.5, "initial_pose.yaw": 1.0,
                                         "initial_pose.std_dev_xy": 0.1,
                                         "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=2)
    sim.drive(1.0)
    assert sim.error() > 0.5  # wrong, and confidently so
    sim.nav_state.set("localizer.reinitialize_global_localization", True)
    errors = sim.drive(25.0)
    assert sim.nav_state.get("localizer.reinitialize_global_localization") is False
    assert np.mean(errors[-100:]) < 0.1, errors[::100]


@pytest.mark.parametrize("seed", [3, 4])
def test_recovers_from_a_kidnapping(seed):
    params = dict(BASE, sensor_model="likelihood_field", num_particles=3000,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=seed)
    sim.drive(4.0)
    assert sim.error() < 0.1
    sim.true[:2] += (1.8, 0.6)  # carried away without odometry
    sim.true[2] += 1.2
    errors = sim.drive(50.0)
    assert np.mean(errors[-100:]) < 0.1, errors[::100]


@pytest.mark.parametrize("seed", [5, 6, 7])
def test_a_robot_carried_to_another_room_is_found_by_sensor_resetting(seed):
    """Carried 6 m into another room with 500 particles: uniform redraws put almost none
    near it (the house's free space is ~80 m², so about 1 in 2000 lands within 0.25 m and
    10°); sensor resetting redraws where the scan fits the map and the cloud finds the robot
    within 10 s of driving."""
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=seed)
    sim.drive(4.0)
    assert sim.error() < 0.1
    sim.true[:] = (0.0, 5.8, 0.0)  # the north corridor, without odometry of the move
    errors = sim.drive(10.0)
    assert errors[0] > 4.0
    assert np.mean(errors[-100:]) < 0.1, errors[::50]


def test_sensor_reset_poses_put_the_true_pose_first():
    costmap = house_costmap()
    rng = np.random.default_rng(0)
    field = likelihood_field(costmap, RESET_STRIDE)
    for truth in [(8.0, 2.5, math.pi), (0.0, 5.8, 0.0), (6.0, 2.0, 1.0)]:
        points = ray_cast(costmap, truth, 180, 6.0, rng)[:, :2]
        poses = sensor_reset_poses(costmap, points, 200, rng, field,
                                   likelihood_field(costmap, RESET_FINE_SIGMA))
        assert poses.shape == (200, 3)
        best = poses[0]
        assert math.hypot(best[0] - truth[0], best[1] - truth[1]) < 0.15, (truth, best)
        assert abs((best[2] - truth[2] + math.pi) % (2 * math.pi) - math.pi) < 0.1
    with pytest.raises(ValueError, match="no scan points"):
        sensor_reset_poses(costmap, np.zeros((0, 2)), 10, rng, field)


def test_global_localisation_parameter_spreads_over_free_space():
    sim = Sim(dict(BASE, global_localization=True, num_particles=2000))
    sim.step(0.0, 0.0, 0.02, correct=True)
    poses = sim.amcl.filter.poses
    assert len(poses) == 2000
    costs = sim.costmap.cost_at(poses[:, 0], poses[:, 1])
    # Spread over the house (not around the initial pose), except where the first
    # correction's reseed moved a few.
    assert (costs == 0).mean() > 0.9 and poses[:, 0].std() > 1.0


def test_kld_count_grows_with_the_spread():
    rng = np.random.default_rng(0)
    # Inside one 0.5 m x 0.5 m x 10° bin: one bin, the minimum.
    tight = np.column_stack((rng.normal(0.25, 0.05, (500, 2)), rng.normal(0.087, 0.02, 500)))
    wide = np.column_stack((rng.uniform(0, 20, (5000, 2)), rng.uniform(-3, 3, 5000)))
    assert kld_particle_count(tight, 0.01, 0.99, 100, 5000) == 100
    assert kld_particle_count(wide, 0.01, 0.99, 100, 5000) == 5000
    # k bins: Fox's bound, computed directly.
    k = 10
    poses = np.column_stack((np.arange(k) * 0.5 + 0.25, np.full(k, 0.25), np.zeros(k)))
    b = 2 / (9 * (k - 1))
    expected = math.ceil((k - 1) / 0.02 * (1 - b + math.sqrt(b) * 0.99) ** 3)
    assert kld_particle_count(poses, 0.01, 0.99, 1, 100000) == expected


def test_beam_likelihood_field_matches_the_formula():
    data = np.zeros((40, 40), dtype=np.uint8)
    data[20, 20] = 254
    costmap = Costmap2D(data, 0.1)
    field, off = beam_likelihood_field(costmap, 0.2, 0.5, 0.5, 10.0, 2.0)
    for ix, iy in ((20, 20), (23, 20), (25, 24), (0, 0)):
        d = min(math.hypot(ix - 20, iy - 20) * 0.1, 2.0)
        pz = 0.5 * math.exp(-0.5 * (d / 0.2) ** 2) + 0.05
        assert field[iy, ix] == pytest.approx(pz**3, rel=1e-4)
    assert off == pytest.approx(0.05**3)


def test_free_space_samples_stay_in_free_cells():
    costmap = house_costmap()
    poses = sample_free_space(costmap, 5000, np.random.default_rng(1))
    assert (costmap.cost_at(poses[:, 0], poses[:, 1]) == 0).all()
    with pytest.raises(ValueError, match="no free cell"):
        sample_free_space(Costmap2D(np.full((3, 3), 254, np.uint8), 0.1), 5,
                          np.random.default_rng(1))


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"num_particles": 0}, "amcl.num_particles = 0: must be >= 1"),
        ({"noise_rotation": 0.0}, "amcl.noise_rotation = 0.0: must be > 0"),
        ({"min_noise_xy": -1.0}, "amcl.min_noise_xy = -1.0: must be > 0"),
        ({"sensor_model": "beam"}, "amcl.sensor_model = 'beam': must be one of"),
        ({"kld_sampling": True, "min_particles": 900, "max_particles": 800},
         "amcl.min_particles = 900 exceeds amcl.max_particles = 800"),
    ],
)
def test_bad_parameters_fail_configuration(params, message):
    with pytest.raises(PluginConfigurationError, match=message):
        Sim(params)


def test_compiled_scoring_agrees_with_the_numpy_reference():
    from easynav.localizers.particle_filter import COMPILED_SCORING, hit_fractions

    if not COMPILED_SCORING.available():
        pytest.skip("numba not installed")
    costmap = house_costmap()
    rng = np.random.default_rng(5)
    poses = np.column_stack((rng.uniform(-3, 3, (500, 2)), rng.uniform(-3, 3, 500)))
    points = ray_cast(costmap, (0.0, 0.0, 0.0), 90, 6.0, rng)[:, :2]
    field, _ = beam_likelihood_field(costmap, 0.2, 0.5, 0.5, 10.0, 2.0)
    fast, fast_n = hit_fractions(poses, points, costmap, field)
    slow, slow_n = hit_fractions(poses, points, costmap, field, compiled=False)
    # float64 against float32 cell arithmetic: a point on a cell edge may flip, rarely.
    assert np.abs(fast - slow).mean() < 1e-4 and np.abs(fast_n - slow_n).max() <= 1


def test_a_search_that_missed_is_tried_again(monkeypatch):
    """The first scan-to-map search after the kidnap puts its particles in the wrong place
    (forced here; seen once in ten playground runs under load). Nav2's reset after a redraw
    restarted both score averages at the lost cloud's low score, and no redraw came again:
    the robot stayed lost. Two seconds after a redraw the localizer searches again, finds a
    place that fits the scan much better than the estimate, and redraws there."""
    import easynav.localizers.costmap_amcl_localizer as module

    real = module.scan_match
    calls = []

    def first_one_misses(costmap, points, *args, **kwargs):
        ranked, fits = real(costmap, points, *args, **kwargs)
        calls.append(ranked[0])
        if len(calls) == 1:  # the wrong room
            return np.tile((8.0, 2.5, math.pi), (len(ranked), 1)), np.full(len(fits), fits[0])
        return ranked, fits

    monkeypatch.setattr(module, "scan_match", first_one_misses)
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=5)
    sim.drive(4.0)
    assert sim.error() < 0.1
    sim.true[:] = (0.0, 5.8, 0.0)  # the north corridor, without odometry of the move
    errors = sim.drive(15.0)
    assert len(calls) >= 2  # searched again after the miss
    assert np.mean(errors[-100:]) < 0.1, errors[::50]


def point_symmetric_hall() -> Costmap2D:
    """A 16 × 8 m hall whose walls and four pillars are symmetric about its centre, with
    pallets in the east half only: the depot's layout in small. A robot in the west half has
    a look-alike place, turned round, in the east half, which its scan of the pallets tells
    apart (the look-alike fits 80-90 % as well)."""
    res = 0.05
    data = np.zeros((160, 320), np.uint8)

    def block(x0, y0, x1, y1):
        data[round(y0 / res):round(y1 / res), round(x0 / res):round(x1 / res)] = 254

    block(0, 0, 16, 0.1)
    block(0, 7.9, 16, 8)
    block(0, 0, 0.1, 8)
    block(15.9, 0, 16, 8)
    for x, y in ((4, 2), (4, 6), (12, 2), (12, 6)):
        block(x - 0.2, y - 0.2, x + 0.2, y + 0.2)
    for x, y in ((10, 1.2), (10.2, 6.6), (13.8, 4.0)):
        block(x - 0.5, y - 0.5, x + 0.5, y + 0.5)
    return Costmap2D(data, res, 0.0, 0.0, "map", 1.0)


def test_a_cloud_settled_on_a_look_alike_place_is_moved_to_the_robot(monkeypatch):
    """The playground's depot is nearly point-symmetric. Once in about thirty runs the cloud
    of the kidnap recovery, which held the robot's place and its mirror image, settled on the
    mirror (which fits the scan 60-90 % as well). Its scores were then where a found robot's
    are, so the search was not tried again, and the score averages (restarted at the lost
    cloud's low score by the redraw) never crossed: the robot drove on 5 m from where it was
    believed to be until the mission timed out. Forced here: the first search returns the
    mirror place only. Two seconds later the localizer searches again; the robot's place fits
    the scan better than the estimate by more than the margin, and the cloud is redrawn
    there."""
    import easynav.localizers.costmap_amcl_localizer as module

    real = module.scan_match
    calls = []
    truth = (3.0, 3.5, math.pi)
    mirror = (16.0 - truth[0], 8.0 - truth[1], 0.0)

    def mirror_first(costmap, points, *args, **kwargs):
        ranked, fits = real(costmap, points, *args, **kwargs)
        calls.append(ranked[0])
        if len(calls) == 1:
            at_mirror = np.hypot(ranked[:, 0] - mirror[0], ranked[:, 1] - mirror[1]) < 0.5
            assert at_mirror.any() and not at_mirror[0]  # a look-alike; the robot's place best
            return ranked[at_mirror], fits[at_mirror]
        return ranked, fits

    monkeypatch.setattr(module, "scan_match", mirror_first)
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.x": 2.0, "initial_pose.y": 2.0,
                     "initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, start=(2.0, 2.0, 0.0), seed=8, costmap=point_symmetric_hall(),
              laser_range=12.0)
    sim.drive(3.0, v=0.2)
    assert sim.error() < 0.1
    sim.true[:] = truth  # carried, without odometry of the move
    errors = sim.drive(10.0, v=0.0)  # turning on the spot
    assert len(calls) >= 2
    assert math.dist(calls[1][:2], sim.true[:2]) < 1.0  # the second search found the robot
    assert np.mean(errors[-100:]) < 0.1, errors[::50]


@pytest.mark.parametrize("seed", [5, 9, 10])
def test_a_robot_carried_twice_is_found_twice(seed):
    """Carried again 12 s after it was found: Nav2's score averages both restart at the first
    score after a redraw, the lost cloud's low one, and the long-term average (alpha 0.001)
    stayed near it for minutes, below the short-term one: the second carry went unnoticed.
    Corrected for their start, the averages are the scores' mean since the redraw, and the
    second drop calls for a search as the first did."""
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=seed)
    sim.drive(4.0)
    sim.true[:] = (0.0, 5.8, 0.0)  # the north corridor, without odometry of the move
    errors = sim.drive(12.0)
    assert np.mean(errors[-100:]) < 0.1, errors[::50]
    sim.true[:] = (6.0, 2.0, 1.0)  # and into the east room
    errors = sim.drive(12.0)
    assert errors[0] > 4.0
    assert np.mean(errors[-100:]) < 0.1, errors[::50]


@pytest.mark.parametrize(("seed", "moved"), [(1, 2), (2, 2), (3, 3)])
def test_a_robot_on_its_place_stays_there_when_the_world_fits_a_look_alike_better(seed, moved):
    """The world differs from the map: ``moved`` of the east pallets stand at their mirror
    places in the west, so the robot's scan fits the map's mirror place better than the
    robot's own (by 7 % with two, 21 % with three; more than the 5 % margin, checked below),
    and two seconds of noisy scans (σ 0.15 m) dip the scores enough for a search. The robot
    has not moved and no place fits the scan 30 % better than its own: nothing is redrawn
    and the cloud stays on it. (Redrawn at the search's places, the cloud followed the
    look-alike 9 m away in 3 seeds of 4.)"""
    from easynav.localizers.costmap_sampling import refined_fit, scan_match

    hall = point_symmetric_hall()
    world = Costmap2D(hall.data.copy(), hall.resolution, 0.0, 0.0, "map", 1.0)
    for x, y in ((10, 1.2), (10.2, 6.6), (13.8, 4.0))[:moved]:  # to their mirror places
        x, y = 16.0 - x, 8.0 - y
        world.data[round((y - 0.5) / 0.05):round((y + 0.5) / 0.05),
                   round((x - 0.5) / 0.05):round((x + 0.5) / 0.05)] = 254
    truth = (3.5, 3.0, 0.0)
    points = ray_cast(world, truth, 180, 12.0, np.random.default_rng(0))[:, :2]
    fine = likelihood_field(hall, RESET_FINE_SIGMA)
    ranked, fits = scan_match(hall, points, likelihood_field(hall, RESET_STRIDE), fine)
    assert math.dist(ranked[0][:2], (16.0 - truth[0], 8.0 - truth[1])) < 0.5
    assert refined_fit(hall, truth, points, fine)[1] < 0.95 * fits[0]

    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.x": truth[0], "initial_pose.y": truth[1],
                     "initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, start=truth, seed=seed, costmap=hall, laser_range=12.0)
    sim.drive(4.0, v=0.0)
    assert sim.error() < 0.1
    sim.costmap = world  # what the laser sees; map.base stays the hall's map
    sim.range_noise = 0.15
    errors = sim.drive(2.0, v=0.0)
    sim.range_noise = 0.01
    errors += sim.drive(16.0, v=0.0)
    assert max(errors) < 0.3, max(errors)


def test_an_initial_pose_given_during_a_kidnap_episode_ends_it():
    """An operator's initialpose overrides the search: the episode ends and the score
    averages start again (Nav2's pf_init), so no check redraws the cloud away from it."""
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=5)
    sim.drive(4.0)
    sim.true[:] = (0.0, 5.8, 0.0)
    for _ in range(100):  # until the first redraw starts an episode
        sim.drive(0.2)
        if sim.amcl._episode is not None:
            break
    assert sim.amcl._episode is not None
    sim.amcl.on_last_known_pose(Odometry(Header(sim.t, "map"), "base_footprint",
                                         Pose.from_xy_yaw(*sim.true)))
    assert sim.amcl._episode is None and sim.amcl._w_slow == 0.0
    errors = sim.drive(4.0)
    assert max(errors) < 0.2


@pytest.mark.parametrize("seed", [1, 3])
def test_a_robot_carried_onto_the_mirror_image_of_its_place_is_found(seed):
    """Carried from (2, 2, 0) onto its mirror place in the hall: the cloud's place fits the new
    scan 70-80 % as well as the robot's, no more than a changed world would, but the scores
    fell by more than half at once (a changed world or noisy scans dip them by a third at
    most): carried, and the cloud is redrawn where the scan fits. Judged on the fits alone, no
    redraw came, and the robot stood 12.7 m from where it was believed to be."""
    start = (2.0, 2.0, 0.0)
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.x": start[0], "initial_pose.y": start[1],
                     "initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, start=start, seed=seed, costmap=point_symmetric_hall(), laser_range=12.0)
    sim.drive(3.0, v=0.0)
    assert sim.error() < 0.1
    sim.true[:] = (16.0 - start[0], 8.0 - start[1], start[2] + math.pi)
    errors = sim.drive(15.0, v=0.0)
    assert errors[0] > 10.0
    assert np.mean(errors[-100:]) < 0.1, errors[::50]


def test_particles_redrawn_after_a_search_are_carried_by_the_odometry_since_the_scan(monkeypatch):
    """The search takes tens of milliseconds (seconds on a loaded machine) and the RT loop
    goes on predicting meanwhile: a robot turning on the spot at 1 rad/s while it searched
    0.4 s had turned 0.4 rad since its scan. The redrawn particles fit the scan where the
    robot was; placed there, a turning robot's cloud trailed behind it and was found late
    (12 s in the depot beside two busy processes). They are carried by the odometry since."""
    import easynav.localizers.costmap_amcl_localizer as module

    real = module.scan_match
    turned = []

    def slow_search(costmap, points, *args, **kwargs):
        result = real(costmap, points, *args, **kwargs)
        for _ in range(20):  # meanwhile, the RT loop: 0.4 s turning at 1 rad/s
            sim.step(0.0, 1.0, 0.02, correct=False)
        turned.append(True)
        return result

    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=5)
    sim.drive(4.0)
    assert sim.error() < 0.1
    monkeypatch.setattr(module, "scan_match", slow_search)
    sim.true[:] = (0.0, 5.8, 0.0)  # the north corridor, without odometry of the move
    for _ in range(200):  # still, scanning, until the first redraw
        sim.step(0.0, 0.0, 0.02, correct=True)
        if turned:
            break
    assert turned and sim.amcl._episode is not None
    poses = sim.amcl.filter.poses
    near = np.hypot(poses[:, 0] - sim.true[0], poses[:, 1] - sim.true[1]) < 0.3
    yaw_error = np.abs((poses[near, 2] - sim.true[2] + math.pi) % (2 * math.pi) - math.pi)
    assert near.sum() > 20
    # On the robot as it is now (0.4 rad on from its scan), within the redraw's spread.
    assert np.median(yaw_error) < 0.1, np.median(yaw_error)


def test_an_initial_pose_away_from_the_searchs_best_place_is_kept(monkeypatch):
    """The operator knows better than the search: during a kidnap episode whose searches all
    prefer the mirror image of the robot's place (forced here: the mirror, said to fit 10 %
    better than anything), an initialpose on the robot's place ends the episode, and no later
    check redraws the cloud toward the search's place (kept, the episode redrew half the cloud
    there 5 times)."""
    import easynav.localizers.costmap_amcl_localizer as module

    real = module.scan_match
    truth = (3.0, 3.5, math.pi)
    mirror = (16.0 - truth[0], 8.0 - truth[1], 0.0)
    calls = []

    def mirror_only(costmap, points, *args, **kwargs):
        ranked, fits = real(costmap, points, *args, **kwargs)
        calls.append(sim.t)
        # The mirror, said to fit 10 % better than the best place found.
        return np.tile(mirror, (len(ranked), 1)), np.full(len(fits), 1.1 * fits[0])

    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.x": 2.0, "initial_pose.y": 2.0,
                     "initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, start=(2.0, 2.0, 0.0), seed=8, costmap=point_symmetric_hall(),
              laser_range=12.0)
    monkeypatch.setattr(module, "scan_match", mirror_only)
    sim.drive(3.0, v=0.2)
    sim.true[:] = truth  # carried, without odometry of the move
    for _ in range(100):  # until the first redraw (at the mirror) starts an episode
        sim.drive(0.2, v=0.0)
        if sim.amcl._episode is not None:
            break
    assert sim.amcl._episode is not None
    sim.amcl.on_last_known_pose(Odometry(Header(sim.t, "map"), "base_footprint",
                                         Pose.from_xy_yaw(*sim.true)))
    searched_before = len(calls)
    errors = sim.drive(12.0, v=0.0)  # turning on the spot
    assert max(errors) < 0.2, max(errors)
    # No search, no redraw toward the mirror: the scores at the given pose did not fall.
    assert sim.amcl._episode is None and len(calls) == searched_before


@pytest.mark.parametrize("seed", [5, 6])
def test_a_redraw_in_a_resample_update_keeps_the_rest_of_the_cloud(seed):
    """A redraw replaces its share of the cloud, no more. When it came in the resample of an
    update whose reseed was due too, the reseed redrew the "worse half" around the better
    one, but after a resample every weight is equal, and the "better half" was the redrawn
    one copied over the rest (twice the share went to the search's places: 0.67 for 0.34), and
    a search that missed had less left where the robot might be. The reseed is skipped then."""
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500, reseed_freq=2.0,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=seed)
    sim.drive(4.0)
    assert sim.error() < 0.1
    before = np.array(sim.amcl.filter.estimate())
    sim.true[:] = (0.0, 5.8, 0.0)  # the north corridor, without odometry of the move
    redraws, reseeds = [], []  # the share redrawn; the redraws before each reseed
    inject, reseed = sim.amcl._inject_random, sim.amcl._reseed

    def recording_inject(base):
        share = sim.amcl._recovery_share()
        redrawn = inject(base)
        if redrawn:
            redraws.append(share)
        return redrawn

    def recording_reseed(base):
        reseeds.append(len(redraws))
        reseed(base)

    sim.amcl._inject_random, sim.amcl._reseed = recording_inject, recording_reseed
    for _ in range(200):  # still, scanning, until the first redraw
        reseeds.clear()
        sim.step(0.0, 0.0, 0.02, correct=True)
        if redraws:
            break
    # The redraw came in the resample (before the reseed), and the reseed was due.
    assert redraws and reseeds == [1], (redraws, reseeds)
    poses = sim.amcl.filter.poses
    kept = np.hypot(poses[:, 0] - before[0], poses[:, 1] - before[1]) < 1.0
    # Everything not redrawn is where the cloud was (the redraw's places are elsewhere).
    assert abs((1.0 - kept.mean()) - redraws[0]) < 0.05, (1.0 - kept.mean(), redraws[0])


def test_a_robot_turning_through_a_slow_update_is_not_taken_for_a_look_alike():
    """The search compares its best place, where the scan was taken, with the cloud's estimate
    as it was then. Compared with the estimate as the RT loop had moved it on while the scan
    was weighed (0.4 s on a loaded machine, at 1.5 rad/s: 0.6 rad), the found robot was
    "elsewhere" from the search's best: every check of the kidnap episode took it for one on
    a look-alike and redrew half its cloud again."""
    params = dict(BASE, sensor_model="likelihood_field", num_particles=500,
                  recovery_alpha_slow=0.001, recovery_alpha_fast=0.1,
                  **{"initial_pose.std_dev_xy": 0.1, "initial_pose.std_dev_yaw": 0.05})
    sim = Sim(params, seed=5)
    sim.drive(4.0)
    weigh, check = sim.amcl._likelihood_field_weights, sim.amcl._check_episode
    checks = []

    def slow_weighing(*args):
        result = weigh(*args)
        for _ in range(20):  # meanwhile, the RT loop: 0.4 s turning at 1.5 rad/s
            sim.step(0.0, 1.5, 0.02, correct=False)
        return result

    def recording_check(lookalike, *args):
        checks.append(lookalike)
        check(lookalike, *args)

    sim.amcl._likelihood_field_weights = slow_weighing
    sim.amcl._check_episode = recording_check
    sim.true[:] = (0.0, 5.8, 0.0)  # the north corridor, without odometry of the move
    errors = []
    for i in range(300):  # turning on the spot, scanning every 0.2 s (and 0.4 s weighing)
        sim.step(0.0, 1.5, 0.02, correct=(i % 10 == 0))
        errors.append(sim.error())
    assert np.mean(errors[-100:]) < 0.1, errors[::50]
    assert checks and not any(checks), checks
