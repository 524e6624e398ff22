"""The multi-level world ``two_floors`` (issue #17): two floors joined by a ramp, without ROS.

The robot driven by direct velocity commands goes up the ramp to the upper floor at the right
height and pitch and back down; under the upper floor it stays on the ground; each level's laser
sees that level's walls (against a direct ray-box computation); the shipped files match their
generator and the walkable-surface mesh lies under every level at the right height.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from easynav.playground.sim import (
    DiffDriveRobot,
    LaserScanner,
    MultiLevelWorld,
    Simulation,
    WheelOdometry,
)
from easynav.playground.sim.ground_truth_recorder import GroundTruthRecorder
from easynav.playground.sim.multilevel import read_ply, write_multilevel_files
from easynav.playground.world_description import WORLDS_DIR, WorldDescription, load_waypoints

DESCRIPTION = WORLDS_DIR / "two_floors.yaml"
RAMP_PITCH = math.atan2(1.5, 4.0)  # the ramp rises 1.5 m over 4 m: 20.6 deg


@pytest.fixture(scope="module")
def description() -> WorldDescription:
    return WorldDescription.resolve("two_floors")


@pytest.fixture(scope="module")
def levels(description) -> MultiLevelWorld:
    return description.make_levels()


def make_sim(description, levels, x, y, yaw, level=None, noise=0.0):
    robot = DiffDriveRobot(x, y, yaw)
    scanner = LaserScanner(beams=360, max_range=8.0, range_noise_std=noise,
                           rng=np.random.default_rng(0))
    odometry = WheelOdometry(rng=np.random.default_rng(1))
    return Simulation(description.world, robot, scanner, odometry, levels=levels,
                      start_level=level)


def drive(sim, v, w, until, limit=60.0):
    """Command ``(v, w)`` and step until ``until(sim)`` or ``limit`` simulated seconds."""
    sim.set_command(v, w)
    end = sim.time + limit
    while sim.time < end and not until(sim):
        sim.step()
    return sim


# ---------------------------------------------------------------------- the description
def test_the_world_declares_its_levels(description, levels):
    assert description.levels is not None and description.terrain_path is None
    assert levels.level_names == ["ground", "upper", "ramp"]
    assert levels.height("upper", 6.0, 4.4) == 1.5 and levels.height("ground", 6.0, 4.4) == 0.0
    assert levels.slope("ramp") == pytest.approx(RAMP_PITCH)
    assert math.degrees(levels.slope("ramp")) < levels.max_climb_slope_deg
    # Flat worlds have no levels.
    assert WorldDescription.resolve("home").make_levels() is None
    waypoints = load_waypoints(description.waypoints_path)
    assert len(waypoints) == 3


def test_malformed_levels_are_refused(tmp_path):
    bad = {"bounds": [0, 0, 4, 4], "floors": [{"name": "a", "z": 0.0, "area": [0, 0, 4, 4]}],
           "ramps": [{"name": "r", "lower": "a", "upper": "nowhere", "area": [1, 1, 2, 2],
                      "rises": "+x"}]}
    with pytest.raises(ValueError, match="must name floors"):
        MultiLevelWorld.from_dict(bad)
    with pytest.raises(ValueError, match="unknown keys"):
        MultiLevelWorld.from_dict({**bad, "ramps": [], "stairs": []})


# ---------------------------------------------------------------------- driving
def test_the_robot_drives_up_the_ramp_to_the_upper_floor(description, levels):
    sim = make_sim(description, levels, 0.55, 5.4, 0.0)
    assert sim.level == "ground" and sim.z == 0.0
    samples = []

    def record(s):
        samples.append((s.robot.x, s.level, s.z, s.pitch))
        return s.robot.x > 6.5

    drive(sim, 0.4, 0.0, record)
    assert sim.level == "upper" and sim.robot.x > 6.5
    assert sim.z == pytest.approx(1.5) and sim.pitch == 0.0
    assert [lv for _, lv in sim.level_events] == ["ground", "ramp", "upper"]
    assert sim.checker.collisions == []
    on_ramp = [(x, z, p) for x, lv, z, p in samples if lv == "ramp"]
    assert on_ramp and min(x for x, _, _ in on_ramp) >= 1.0 and max(x for x, _, _ in on_ramp) <= 5.0
    for x, z, p in on_ramp:
        assert z == pytest.approx(1.5 * (x - 1.0) / 4.0)
        assert p == pytest.approx(-RAMP_PITCH)  # REP-103: nose up is a negative pitch
    # On the slope the wheels' distance is laid along it: the horizontal speed is v cos(pitch).
    xs = [x for x, lv, _, _ in samples if lv == "ramp"]
    speed = (xs[-1] - xs[0]) / ((len(xs) - 1) * sim.step_size)
    assert speed == pytest.approx(0.4 * math.cos(RAMP_PITCH), rel=1e-3)
    # The ground truth: (x, y, yaw) poses with the level, the height and the pitch.
    rec = sim.recorder
    assert len(rec.levels) == len(rec.true_poses) > 0
    assert {lv for _, lv, _, _ in rec.levels} == {"ground", "ramp", "upper"}
    assert max(z for _, _, z, _ in rec.levels) == pytest.approx(1.5)
    assert rec.max_slope() == pytest.approx(RAMP_PITCH)


def test_the_robot_drives_back_down_to_the_ground(description, levels):
    sim = make_sim(description, levels, 6.0, 5.4, math.pi, level="upper")
    seen_pitch = []
    drive(sim, 0.4, 0.0, lambda s: seen_pitch.append(s.pitch) or s.robot.x < 0.6)
    assert sim.level == "ground" and sim.z == 0.0 and sim.checker.collisions == []
    assert [lv for _, lv in sim.level_events] == ["upper", "ramp", "ground"]
    assert max(seen_pitch) == pytest.approx(RAMP_PITCH)  # nose down going down


def test_under_the_upper_floor_the_robot_stays_on_the_ground(description, levels):
    # The same line at both levels (y = 4.9, east): the ground's robot hits the crate under the
    # mezzanine, the upper floor's drives over it to the east wall.
    ground = drive(make_sim(description, levels, 5.6, 4.9, 0.0), 0.3, 0.0, lambda s: False, 10.0)
    assert ground.level == "ground" and ground.z == 0.0
    assert ground.robot.x == pytest.approx(6.9 - 0.2, abs=0.01)
    assert [c.with_what for c in ground.checker.collisions] == ["wall"]
    upper = drive(make_sim(description, levels, 5.6, 4.9, 0.0, level="upper"), 0.3, 0.0,
                  lambda s: False, 10.0)
    assert upper.level == "upper" and upper.z == 1.5
    assert upper.robot.x == pytest.approx(7.9 - 0.2, abs=0.01)
    # West along y = 5.4 under the mezzanine: the ground's robot stops at the wall under the
    # ramp's top; it never gets onto the ramp or the upper floor from below.
    west = drive(make_sim(description, levels, 6.0, 5.4, math.pi), 0.3, 0.0, lambda s: False, 10.0)
    assert west.level == "ground" and west.robot.x == pytest.approx(5.0 + 0.2, abs=0.01)
    assert [lv for _, lv in west.level_events] == ["ground"]
    # A turn on the spot under the mezzanine keeps the robot on the ground.
    spin = drive(make_sim(description, levels, 6.0, 4.4, 0.0), 0.0, 1.0, lambda s: False, 7.0)
    assert spin.level == "ground" and spin.checker.collisions == []


def test_a_ramp_steeper_than_the_climb_limit_stops_the_robot(description):
    steep = MultiLevelWorld.from_dict({**description.levels, "max_climb_slope_deg": 15.0})
    sim = drive(make_sim(description, steep, 0.55, 5.4, 0.0), 0.4, 0.0, lambda s: False, 5.0)
    assert sim.level == "ground" and sim.robot.x < 1.01
    assert [c.with_what for c in sim.checker.collisions] == ["steep slope (20.6 deg > 15)"]


def test_level_samples_survive_the_record_file(tmp_path):
    rec = GroundTruthRecorder()
    rec.record_true(0.1, 1.0, 5.4, 0.0)
    rec.record_level(0.1, "ramp", 0.2, -0.35)
    rec.save(tmp_path / "truth.json")
    assert GroundTruthRecorder.load(tmp_path / "truth.json").levels == [(0.1, "ramp", 0.2, -0.35)]
    assert "levels" not in GroundTruthRecorder().to_dict()


# ---------------------------------------------------------------------- the laser
def _ray_box(ox, oy, angle, box):
    """Distance from ``(ox, oy)`` along ``angle`` to the axis-aligned ``box`` (inf: missed)."""
    x0, y0, x1, y1 = box
    dx, dy = math.cos(angle), math.sin(angle)
    lo, hi = 0.0, math.inf
    for o, d, a, b in ((ox, dx, x0, x1), (oy, dy, y0, y1)):
        if abs(d) < 1e-12:
            if not a <= o <= b:
                return math.inf
            continue
        t0, t1 = sorted(((a - o) / d, (b - o) / d))
        lo, hi = max(lo, t0), min(hi, t1)
    return lo if lo <= hi else math.inf


def _boxes_at_height(levels, h):
    """What a level scan plane at height ``h`` meets: solids, floor slabs and the part of each
    ramp's wedge that rises above ``h``, as 2D boxes."""
    boxes = [(s.x0, s.y0, s.x1, s.y1) for s in levels.solids if s.z0 <= h <= s.z1]
    boxes += [f.area for f in levels.floors if f.z - f.thickness <= h <= f.z]
    for r in levels.ramps:
        if r.z_low <= h <= r.z_high:
            assert r.rises == "+x"
            u = r.foot + (h - r.z_low) / (r.z_high - r.z_low) * (r.top - r.foot)
            boxes.append((u, r.area[1], r.area[2], r.area[3]))
    return boxes


@pytest.mark.parametrize(("level", "x", "y", "yaw"), [
    ("ground", 6.0, 4.85, 0.0),   # under the mezzanine, beside the crate
    ("upper", 6.0, 4.85, 0.0),    # the same (x, y) on the mezzanine
    ("ground", 1.0, 1.0, 0.7),    # the start
    ("ground", 0.5, 4.4, 0.3),    # before the ramp's foot: the ramp's surface rises in view
    ("upper", 7.0, 4.3, 2.0),
])
def test_the_laser_on_a_floor_sees_that_floors_walls(description, levels, level, x, y, yaw):
    sim = make_sim(description, levels, x, y, yaw, level=level)
    ranges = sim.scan_now()
    lx, ly, lyaw = sim.laser_pose()
    h = levels.height(level, x, y) + levels.laser_height
    boxes = _boxes_at_height(levels, h)
    expected = np.array([min(_ray_box(lx, ly, a + lyaw, b) for b in boxes)
                         for a in sim.scanner.angles])
    expected[expected > sim.scanner.max_range] = np.inf
    both = np.isfinite(expected) & np.isfinite(ranges)
    assert (np.isfinite(expected) == np.isfinite(ranges)).mean() > 0.99
    # The grid is 0.05 m: a ray meets a wall's cell up to a cell diagonal early.
    err = ranges[both] - expected[both]
    assert np.abs(err).max() <= 0.075 and np.abs(np.median(err)) <= 0.03


def test_the_laser_sees_the_levels_apart(description, levels):
    """Beams of the parametrised poses, by hand: east, south and west at (6.1, 4.85)."""
    east, south, west = (int(np.argmin(np.abs(LaserScanner(360).angles - a)))
                         for a in (0.0, -math.pi / 2, math.pi))
    ground = make_sim(description, levels, 6.0, 4.85, 0.0).scan_now()
    upper = make_sim(description, levels, 6.0, 4.85, 0.0, level="upper").scan_now()
    assert ground[east] == pytest.approx(6.9 - 6.1, abs=0.05)   # the crate
    assert upper[east] == pytest.approx(7.9 - 6.1, abs=0.05)    # over it: the east wall
    assert ground[south] == pytest.approx(4.85 - 0.1, abs=0.05)  # down to the south wall
    assert upper[south] == pytest.approx(4.85 - 3.6, abs=0.05)  # the railing
    assert ground[west] == pytest.approx(6.1 - 5.0, abs=0.05)   # the ramp's side wall, below
    assert upper[west] == pytest.approx(6.1 - 5.1, abs=0.05)    # the west railing


def test_the_laser_on_the_ramp_pitches_with_it(description, levels):
    sim = make_sim(description, levels, 3.0, 5.4, 0.0, level="ramp")
    ranges = sim.scan_now()
    lx = sim.laser_pose()[0]
    beam = {name: int(np.argmin(np.abs(sim.scanner.angles - a)))
            for name, a in (("east", 0.0), ("north", math.pi / 2), ("south", -math.pi / 2),
                            ("west", math.pi))}
    stretch = 1.0 / math.cos(RAMP_PITCH)
    # Across the ramp: its side walls, level.
    assert ranges[beam["north"]] == pytest.approx(0.5, abs=0.05)
    assert ranges[beam["south"]] == pytest.approx(0.5, abs=0.05)
    # Up the ramp the plane, 0.25 m over the surface, passes over the mezzanine to the east
    # wall (at 7.9 the plane is 2.84 m up: under its 3 m top); the beam is longer than its
    # horizontal advance.
    assert ranges[beam["east"]] == pytest.approx((7.9 - lx) * stretch, abs=0.08)
    # Down the ramp it meets the ground floor beyond the foot, where the plane reaches z = 0.
    foot_hit = 1.0 - levels.laser_height / math.tan(RAMP_PITCH)
    assert ranges[beam["west"]] == pytest.approx((lx - foot_hit) * stretch, abs=0.08)


# ---------------------------------------------------------------------- files and mesh
def test_shipped_two_floors_files_match_their_generator(tmp_path):
    write_multilevel_files(DESCRIPTION, tmp_path)
    for name in ("two_floors.walkable.ply", "maps/two_floors_ground.yaml",
                 "maps/two_floors_ground.pgm", "maps/two_floors_upper.yaml",
                 "maps/two_floors_upper.pgm"):
        assert (WORLDS_DIR / name).read_bytes() == (tmp_path / name).read_bytes(), name


def _heights_at(vertices, faces, x, y):
    """Heights of the mesh's triangles whose projection holds ``(x, y)``."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    v0, v1 = b[:, :2] - a[:, :2], c[:, :2] - a[:, :2]
    p = np.array([x, y]) - a[:, :2]
    det = v0[:, 0] * v1[:, 1] - v0[:, 1] * v1[:, 0]
    u = (p[:, 0] * v1[:, 1] - p[:, 1] * v1[:, 0]) / det
    v = (v0[:, 0] * p[:, 1] - v0[:, 1] * p[:, 0]) / det
    inside = (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9)
    z = a[:, 2] + u * (b[:, 2] - a[:, 2]) + v * (c[:, 2] - a[:, 2])
    return z[inside]


def test_the_mesh_covers_every_levels_walkable_surface(levels):
    vertices, faces = read_ply(WORLDS_DIR / "two_floors.walkable.ply")
    assert faces.shape[1] == 3 and len(faces) > 1000
    rng = np.random.default_rng(3)
    for level in levels.level_names:
        surface = levels.surface(level)
        walls = levels.collision_world(level)
        x0, y0, x1, y1 = surface.area
        checked = 0
        for x, y in zip(rng.uniform(x0, x1, 400), rng.uniform(y0, y1, 400), strict=True):
            # Walkable: off the walls (a cell's margin) and, on a floor, not under a ramp.
            if walls.distance_to_occupied(x, y, 0.1) < 0.1:
                continue
            if level != "ramp" and levels.in_area("ramp", x, y):
                continue
            zs = _heights_at(vertices, faces, x, y)
            assert np.any(np.abs(zs - levels.height(level, x, y)) < 1e-3), (level, x, y, zs)
            checked += 1
        assert checked > 100, level
    # Two surfaces under the mezzanine, one elsewhere; nothing on a wall.
    assert sorted(np.round(_heights_at(vertices, faces, 6.03, 4.47), 6)) == [0.0, 1.5]
    assert list(np.round(_heights_at(vertices, faces, 2.03, 2.07), 6)) == [0.0]
    assert _heights_at(vertices, faces, 3.05, 1.07).size == 0  # the partition


def test_the_mesh_joins_the_floors_through_the_ramp(levels, description):
    vertices, faces = read_ply(WORLDS_DIR / "two_floors.walkable.ply")
    parent = list(range(len(vertices)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, c in faces:
        for u, v in ((a, b), (b, c)):
            parent[find(u)] = find(v)

    def vertex_near(x, y, z):
        return int(np.argmin(np.linalg.norm(vertices - np.array([x, y, z]), axis=1)))

    start = vertex_near(*description.start_pose[:2], 0.0)
    assert find(start) == find(vertex_near(6.5, 4.4, 1.5))  # the upper waypoint


# ---------------------------------------------------------------------- the demo's verdict
def test_a_waypoint_reached_on_another_level_is_not_reached(description):
    from easynav.playground.demo.run_summary import RunSummary
    from easynav.playground.demo.waypoint_result import WaypointResult
    from easynav.playground.world_description import load_waypoint_levels

    levels = load_waypoint_levels(description.waypoints_path)
    assert levels == ["upper", "ground", "ground"]
    assert load_waypoint_levels(WORLDS_DIR / "home.waypoints.yaml") is None
    truth = GroundTruthRecorder()
    for i in range(30):  # the robot stays on the ground floor (a 2D stack)
        truth.record_true(0.1 * i, 1.0 + 0.2 * i, 1.0, 0.0)
        truth.record_level(0.1 * i, "ground", 0.0, 0.0)
    results = [WaypointResult(1, 6.5, 4.4, 0.0, reached_at=1.0, level="upper"),
               WaypointResult(2, 4.0, 1.2, 0.0, reached_at=2.0, level="ground")]
    summary = RunSummary.compute(results, truth, "NAVIGATION_FINISHED", "", 0.0, 2.9, 10.0)
    assert [w.arrival_level for w in results] == ["ground", "ground"]
    assert not results[0].achieved and results[1].achieved
    assert not summary.success and summary.to_dict()["reached_on_wrong_level"] == 1
    table = summary.format_table()
    assert "LEVEL" in table and "waypoints reached:    1 of 2" in table
    assert "waypoint 1 reached on level ground, not on its level upper" in table
    # Flat worlds: no level samples, nothing changes.
    flat = [WaypointResult(1, 6.5, 4.4, 0.0, reached_at=1.0)]
    assert RunSummary.compute(flat, GroundTruthRecorder(), "X", "", 0.0, 1.0, 0.0).all_reached


def test_the_mesh_loads_as_one_navmap_surface_with_two_floors():
    """The NavMap stack's mesh builder (easynav-maps) reads the shipped PLY: one connected
    surface, and the same (x, y) under the mezzanine locates two NavCels, at 0 and 1.5 m."""
    builders = pytest.importorskip("easynav.maps.navmap.builders")
    navmap = builders.navmap_from_mesh_file(WORLDS_DIR / "two_floors.walkable.ply")
    assert len(navmap.surfaces) == 1
    low = navmap.locate_navcel(np.array([6.53, 4.47, 0.0]))
    high = navmap.locate_navcel(np.array([6.53, 4.47, 1.5]))
    assert low is not None and high is not None and low != high
    assert navmap.centroids[low][2] == pytest.approx(0.0)
    assert navmap.centroids[high][2] == pytest.approx(1.5)
