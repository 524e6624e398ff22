"""The demo's pieces without ROS: params derivation, summary figures, the picture, progress."""

from __future__ import annotations

import io
import math

import pytest
import yaml

from easynav.playground.demo.demo import DEFAULT_PARAMS, build_parser, run_demo
from easynav.playground.demo.params_patch import derive_params, pose_estimate_topic
from easynav.playground.demo.progress_line import ProgressLine
from easynav.playground.demo.run_monitor import compose
from easynav.playground.demo.run_plot import plot_run
from easynav.playground.demo.run_summary import RunSummary
from easynav.playground.demo.waypoint_result import WaypointResult
from easynav.playground.sim import GroundTruthRecorder
from easynav.playground.world_description import WorldDescription


def test_derived_params_point_the_simple_stack_at_the_world(tmp_path):
    out = tmp_path / "params.yaml"
    notes, path_topic = derive_params(DEFAULT_PARAMS, tmp_path / "w.map", (1.0, 2.0, 0.5), out)
    params = yaml.safe_load(out.read_text())
    maps = params["maps_manager_node"]["ros__parameters"]["simple"]
    assert maps["package"] == "" and maps["map_path_file"] == str(tmp_path / "w.map")
    pose = params["localizer_node"]["ros__parameters"]["simple"]["initial_pose"]
    assert (pose["x"], pose["y"], pose["yaw"]) == (1.0, 2.0, 0.5)
    assert all(s["ros__parameters"]["use_sim_time"] is True for s in params.values())
    assert path_topic == "/planner_node/simple/path"
    assert any("initial_pose" in n for n in notes)


def test_derived_params_handle_flat_keys_and_turn_sim_time_on(tmp_path):
    source = tmp_path / "flat.yaml"
    source.write_text(
        "maps_manager_node:\n  ros__parameters:\n    map_types: [m]\n"
        "    m.plugin: easynav_simple_maps_manager/SimpleMapsManager\n    m.map_path_file: x.map\n"
        "planner_node:\n  ros__parameters:\n    use_sim_time: false\n"
    )
    out = tmp_path / "out.yaml"
    notes, path_topic = derive_params(source, tmp_path / "w.map", (0, 0, 0), out)
    params = yaml.safe_load(out.read_text())
    assert params["maps_manager_node"]["ros__parameters"]["m.map_path_file"] == str(
        tmp_path / "w.map"
    )
    assert params["planner_node"]["ros__parameters"]["use_sim_time"] is True
    assert any("planner_node.use_sim_time" in n for n in notes)
    assert path_topic is None


def test_serest_keeps_its_margin_beyond_the_worlds_robot(tmp_path):
    # d0_margin is from the robot's centre: a file written for the 0.15 m TurtleBot3 (0.20)
    # would let the campus's 0.3 m robot touch a wall before SeReST stops; a larger one stays.
    source = tmp_path / "serest.yaml"
    source.write_text(
        "controller_node:\n  ros__parameters:\n    controller_types: [a, b, c]\n"
        "    a: {plugin: easynav_serest_controller/SerestController, d0_margin: 0.2}\n"
        "    b: {plugin: easynav_serest_controller/SerestController, d0_margin: 0.5}\n"
        "    c: {plugin: easynav_serest_controller/SerestController}\n"
    )
    raised = {}
    for radius, expected in ((0.3, (0.35, 0.5, 0.35)), (0.15, (0.2, 0.5, 0.3))):
        out = tmp_path / "out.yaml"
        notes, _ = derive_params(source, tmp_path / "w.map", (0, 0, 0), out, robot_radius=radius)
        controllers = yaml.safe_load(out.read_text())["controller_node"]["ros__parameters"]
        assert tuple(controllers[k].get("d0_margin", 0.3) for k in "abc") == expected
        raised[radius] = [n for n in notes if "d0_margin" in n]
    assert raised[0.15] == []
    assert raised[0.3] == [
        "controller_node.a.d0_margin 0.2 -> 0.35: the world's robot is 0.3 m (the margin is "
        "from its centre)",
        "controller_node.c.d0_margin 0.3 -> 0.35: the world's robot is 0.3 m (the margin is "
        "from its centre)",
    ]


def test_not_a_params_file_is_refused(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("just: text\n")
    with pytest.raises(ValueError, match="ros__parameters"):
        derive_params(bad, tmp_path / "w.map", (0, 0, 0), tmp_path / "o.yaml")


def make_truth():
    truth = GroundTruthRecorder()
    for k in range(101):  # 10 s driving +x at 0.1 m/s
        truth.record_true(k * 0.1, 0.1 * k * 0.1, 0.0, 0.0)
        truth.record_clearance(k * 0.1, 0.01 * k, 0.0, 0.5 - 0.001 * k)
        truth.record_estimate(k * 0.1, 0.01 * k + 0.05, 0.0, 0.0)
    return truth


def test_summary_legs_clearance_and_localisation_error():
    waypoints = [WaypointResult(1, 0.5, 0.0, 0.0, reached_at=5.0), WaypointResult(2, 2.0, 0.0, 0.0)]
    summary = RunSummary.compute(waypoints, make_truth(), "TIMEOUT", "", 0.0, 10.0, 20.0)
    assert waypoints[0].leg_time == pytest.approx(5.0)
    assert waypoints[0].leg_distance == pytest.approx(0.5)
    assert waypoints[0].arrival_error == pytest.approx(0.0, abs=1e-9)
    assert summary.distance_driven == pytest.approx(1.0)
    assert summary.min_clearance == pytest.approx(0.4)
    assert summary.localisation_mean == pytest.approx(0.05)
    assert not summary.all_reached and not summary.success
    table = summary.format_table()
    assert "NO" in table and "1 of 2" in table and "FAILURE" in table and "20.0 Hz" in table


def test_summary_success_needs_every_waypoint_and_no_collision():
    truth = make_truth()
    waypoints = [WaypointResult(1, 0.5, 0.0, 0.0, reached_at=5.0)]
    ok = RunSummary.compute(waypoints, truth, "NAVIGATION_FINISHED", "", 0.0, 10.0, 20.0)
    assert ok.success and "SUCCESS" in ok.format_table()
    truth.record_collision({"stamp": 3.0, "x": 0.3, "y": 0.0, "with": "wall"})
    hit = RunSummary.compute(waypoints, truth, "NAVIGATION_FINISHED", "", 0.0, 10.0, 20.0)
    assert not hit.success and "collision with wall" in hit.format_table()


def test_picture_of_a_run_is_written(tmp_path):
    import numpy as np

    home = WorldDescription.resolve("home")
    truth = make_truth()
    out = tmp_path / "run.png"
    plot_run(
        out,
        home.world,
        [WaypointResult(1, 5.6, 6.4, 1.57, reached_at=3.0), WaypointResult(2, 2.4, 5.0, 3.14)],
        home.start_pose,
        truth.true_poses,
        truth.estimated_poses,
        [np.array([(5.6, 3.4), (5.6, 6.4)])],
        [{"stamp": 1.0, "x": 5.0, "y": 5.0, "with": "wall"}],
        home.make_obstacles(),
        title="test",
    )
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_progress_line_redraws_on_a_terminal_and_prints_lines_otherwise():
    class Tty(io.StringIO):
        def isatty(self):
            return True

    tty = Tty()
    line = ProgressLine(tty)
    line.show("waypoint 1 of 4", force=True)
    line.show("wp 2", force=True)
    line.finish()
    assert tty.getvalue() == "\rwaypoint 1 of 4\rwp 2           \n"
    pipe = io.StringIO()
    line = ProgressLine(pipe, period=100.0)
    line.show("a", force=True)
    line.show("b")  # too soon: skipped
    assert pipe.getvalue() == "a\n"


def test_pose_composition():
    x, y, yaw = compose((1.0, 2.0, math.pi / 2), (1.0, 0.0, 0.1))
    assert (x, y, yaw) == pytest.approx((1.0, 3.0, math.pi / 2 + 0.1))


def test_bad_demo_arguments_exit_2_naming_the_problem(tmp_path, capsys):
    assert run_demo(world="atlantis", output_png=None) == 2
    assert "atlantis" in capsys.readouterr().err
    bad = tmp_path / "w.yaml"
    bad.write_text("waypoints: [[1, 2]]\n")
    assert run_demo(world="home", waypoints=bad, output_png=None) == 2
    assert "waypoint 0" in capsys.readouterr().err
    assert build_parser().parse_args(["--speed-up", "2"]).speed_up == 2.0


def test_derived_params_point_the_costmap_manager_at_the_map_yaml(tmp_path):
    source = tmp_path / "costmap.yaml"
    source.write_text(
        "maps_manager_node:\n  ros__parameters:\n    map_types: [costmap]\n    costmap:\n"
        "      plugin: easynav_costmap_maps_manager/CostmapMapsManager\n"
        "      package: easynav_playground\n      map_path_file: worlds/maps/depot.yaml\n"
        "system_node:\n  ros__parameters:\n    robot_geometry: {radius: 0.3}\n"
    )
    out = tmp_path / "out.yaml"
    notes, _ = derive_params(
        source, tmp_path / "w.map", (0, 0, 0), out, map_yaml=tmp_path / "w.yaml", robot_radius=0.15
    )
    params = yaml.safe_load(out.read_text())
    maps = params["maps_manager_node"]["ros__parameters"]["costmap"]
    assert maps["package"] == "" and maps["map_path_file"] == str(tmp_path / "w.yaml")
    system = params["system_node"]["ros__parameters"]
    assert system["robot_geometry"]["radius"] == 0.15 and system["use_sim_time"] is True
    assert any("robot_geometry.radius = 0.15" in n for n in notes)


def test_an_inscribed_radius_smaller_than_the_worlds_robot_is_raised(tmp_path):
    # The inflation filters' cost 253 must reach the world's robot (a disc); a larger one stays.
    for inscribed, expected in ((0.2, 0.3), (0.4, 0.4)):
        source = tmp_path / "small.yaml"
        source.write_text(
            "system_node:\n  ros__parameters:\n"
            f"    robot_geometry: {{radius: 0.2, inscribed_radius: {inscribed}}}\n"
        )
        out = tmp_path / "out.yaml"
        notes, _ = derive_params(source, tmp_path / "w.map", (0, 0, 0), out, robot_radius=0.3)
        system = yaml.safe_load(out.read_text())["system_node"]["ros__parameters"]
        assert system["robot_geometry"]["inscribed_radius"] == expected
        raised = [n for n in notes if "inscribed_radius" in n]
        assert raised == ([
            "system_node.robot_geometry.inscribed_radius 0.2 -> 0.3, the world's robot (a disc)"
        ] if inscribed < 0.3 else [])


def test_derived_params_point_the_voxel_maps_managers_at_the_world(tmp_path):
    import yaml

    source = tmp_path / "voxels.params.yaml"
    source.write_text(
        "maps_manager_node:\n  ros__parameters:\n    map_types: [octo, bonxai]\n"
        "    octo:\n      plugin: easynav_octomap_maps_manager/OctomapMapsManager\n"
        "      package: easynav_playground\n      octomap_path_file: maps/x.bt\n"
        "    bonxai:\n      plugin: easynav_bonxai_maps_manager/BonxaiMapsManager\n"
        "      bonxai_path_file: /some/cloud.pcd\n"
    )
    out = tmp_path / "out.yaml"
    notes, _ = derive_params(
        source, tmp_path / "w.map", (0, 0, 0), out, map_yaml=tmp_path / "w.yaml",
        robot_radius=0.2, robot_height=0.5,
    )
    maps = yaml.safe_load(out.read_text())["maps_manager_node"]["ros__parameters"]
    assert maps["octo"]["occmap_path_file"] == str(tmp_path / "w.yaml")
    assert maps["octo"]["octomap_path_file"] == "" and maps["octo"]["package"] == ""
    assert maps["bonxai"]["occmap_path_file"] == str(tmp_path / "w.yaml")
    assert maps["bonxai"]["bonxai_path_file"] == ""
    system = yaml.safe_load(out.read_text())["system_node"]["ros__parameters"]
    assert system["robot_geometry"] == {"radius": 0.2, "height": 0.5}
    assert any("extrudes" in n for n in notes)


def test_the_controller_cycle_is_read_from_easynavs_log(tmp_path):
    from easynav.playground.demo.demo_run import controller_cycle_from_log

    log = tmp_path / "easynav.log"
    assert controller_cycle_from_log(log) is None  # no log
    log.write_text(
        "[INFO] [1.0] [planner_node]: cycle time of costmap (easynav_costmap_planner/"
        "CostmapPlanner).update: 90 runs, median 12.000 ms, p99 30.000 ms, max 31.000 ms\n"
        "[INFO] [1.0] [controller_node]: cycle time of rpp (easynav_regulated_pp_controller/"
        "RegulatedPurePursuitController).update_rt: 2931 runs, median 0.310 ms, "
        "p99 1.200 ms, max 3.400 ms\n"
    )
    cycle = controller_cycle_from_log(log)
    assert cycle == {
        "alias": "rpp", "plugin": "easynav_regulated_pp_controller/RegulatedPurePursuitController",
        "runs": 2931, "median_ms": 0.31, "p99_ms": 1.2, "max_ms": 3.4,
    }
    summary = RunSummary.compute([], make_truth(), "NAVIGATION_FINISHED", "", 0.0, 10.0, 20.0)
    summary.controller_cycle = cycle
    assert "controller cycle:     median 0.31 ms, p99 1.20 ms, max 3.40 ms (rpp: " in (
        summary.format_table())


def test_the_odometry_transforms_age_is_read_from_easynavs_log(tmp_path):
    from easynav.playground.demo.demo_run import odometry_age_from_log

    log = tmp_path / "easynav.log"
    assert odometry_age_from_log(log) is None  # no log
    log.write_text("[INFO] [1.0] [system_node]: EasyNav is active\n")
    assert odometry_age_from_log(log) is None  # no line
    log.write_text(
        "[INFO] [9.0] [system_node]: age of odom → base_footprint when served: 400 "
        "transforms, median 1.5 ms, p99 20.0 ms, max 80.0 ms\n"
        "[INFO] [19.0] [system_node]: age of odom → base_footprint when served: 900 "
        "transforms, median -2.5 ms, p99 31.5 ms, max 1300.2 ms\n"
    )
    age = odometry_age_from_log(log)
    assert age == {"transforms": 900, "median_ms": -2.5, "p99_ms": 31.5, "max_ms": 1300.2}
    summary = RunSummary.compute([], make_truth(), "NAVIGATION_FINISHED", "", 0.0, 10.0, 20.0)
    summary.odometry_age = age
    assert summary.to_dict()["odometry_age"] == age
    assert "odom TF age served:   median -2.5 ms, p99 31.5 ms, max 1300.2 ms (900 " in (
        summary.format_table())


def test_the_gps_localizers_estimate_is_read_from_its_topic(tmp_path):
    """The demo scores the pose the GpsLocalizer publishes on robot/odom_gps (the original's
    map -> odom was a static identity); every other localizer is read from TF."""
    params = tmp_path / "p.yaml"
    gps = {"plugin": "easynav_gps_localizer/GpsLocalizer"}
    localizer = {"localizer_types": ["gps"], "gps": gps}
    params.write_text(yaml.safe_dump({"localizer_node": {"ros__parameters": localizer}}))
    assert pose_estimate_topic(params) == "/robot/odom_gps"
    assert pose_estimate_topic(DEFAULT_PARAMS) is None
    assert pose_estimate_topic(tmp_path / "missing.yaml") is None


def test_a_waypoint_is_stamped_when_the_goal_manager_said_it_was_reached():
    """The feedback that lists one goal fewer is stamped by the goal manager (EasyNav's
    simulated clock): that is when the waypoint was reached, not the newest true time this
    process has seen when it read the feedback (under load its queue ran 16 s behind, and a
    waypoint of the upper floor was scored where the robot then was, 4 m away on the ramp)."""
    from types import SimpleNamespace

    from easynav.core.types import Goals, Header, PoseStamped
    from easynav.playground.demo.demo_run import DemoRun
    from easynav.playground.demo.waypoint_result import WaypointResult
    from easynav.system.goals.goal_client_state import GoalClientState
    from easynav.system.goals.navigation_control import NavigationControl

    run = SimpleNamespace(
        monitor=SimpleNamespace(truth=(59.0, 1.2, 5.5, 3.1), remaining_goals=None),
        results=[WaypointResult(1, 6.5, 4.4, 0.0), WaypointResult(2, 4.0, 1.2, 0.0),
                 WaypointResult(3, 6.0, 4.4, 1.57)],
        client=SimpleNamespace(get_result=lambda: None),
    )
    feedback = NavigationControl(header=Header(42.5, "map"),
                                 goals=Goals(goals=[PoseStamped(), PoseStamped()]))
    DemoRun._mark_reached(run, GoalClientState.ACCEPTED_AND_NAVIGATING, feedback)
    assert [w.reached_at for w in run.results] == [42.5, None, None]
    # A stamp from the future (another clock) is taken as the newest true time.
    feedback = NavigationControl(header=Header(1e9, "map"), goals=Goals(goals=[PoseStamped()]))
    DemoRun._mark_reached(run, GoalClientState.ACCEPTED_AND_NAVIGATING, feedback)
    assert [w.reached_at for w in run.results] == [42.5, 59.0, None]
    run.client = SimpleNamespace(get_result=lambda: NavigationControl(header=Header(70.0, "map")))
    run.monitor = SimpleNamespace(truth=(75.0, 6.0, 4.4, 1.57), remaining_goals=None)
    DemoRun._mark_reached(run, GoalClientState.NAVIGATION_FINISHED, None)
    assert [w.reached_at for w in run.results] == [42.5, 59.0, 70.0]
