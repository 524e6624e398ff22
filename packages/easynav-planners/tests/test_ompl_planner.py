"""OMPLPlanner plugin without ROS: NavState in and out, replanning, rejection, parameters."""

from __future__ import annotations

import itertools
import math
from pathlib import Path as FilePath

import numpy as np
import pytest

from easynav.core.nav_state import NavState
from easynav.core.plugins import (
    DictParameters,
    ParameterValueError,
    PluginConfigurationError,
    PluginContext,
)
from easynav.core.robot import RobotGeometry
from easynav.core.types import (
    Costmap2D,
    DiagnosticLevel,
    DiagnosticStatus,
    Goals,
    Header,
    Odometry,
    Path,
    Pose,
    PoseStamped,
)
from easynav.maps import SimpleMap

pytest.importorskip("ompl", reason="the OMPL planner needs the [ompl] extra")

from easynav.planners.ompl_planner import OMPLPlanner  # noqa: E402

_namespaces = itertools.count()


def room() -> Costmap2D:
    """8 m x 4 m, walls around, a wall at x = 4 m with a door at y 2.4..4.0 (as SimplePlanner's
    test world)."""
    costmap = Costmap2D.filled(160, 80, 0.05)
    costmap.data[0, :] = costmap.data[-1, :] = costmap.data[:, 0] = costmap.data[:, -1] = 254
    costmap.data[0:48, 80:82] = 254
    return costmap


def make_planner(params=None, geometry=None) -> OMPLPlanner:
    # A long budget: RRTConnect stops at its first solution, however loaded the machine is.
    values = {"seed": 3, "solve_time": 60.0, "clearance_distance": 0.1, **(params or {})}
    context = PluginContext(
        parameters=DictParameters({f"ompl.{k}": v for k, v in values.items()}),
        namespace=f"ompl_test_{next(_namespaces)}",
        now=lambda: 7.0,
        robot_geometry=lambda: geometry or RobotGeometry(radius=0.25),
    )
    planner = OMPLPlanner()
    planner.initialize(context, "ompl")
    return planner


def state_with(goal_xy_yaw, robot_xy=(1.0, 1.0), world=None, frame="map") -> NavState:
    nav_state = NavState()
    nav_state.set("map", world if world is not None else room())
    set_robot(nav_state, robot_xy)
    goal = PoseStamped(Header(5.0, frame), Pose.from_xy_yaw(*goal_xy_yaw))
    nav_state.set("goals", Goals(Header(5.0, frame), [goal]))
    return nav_state


def set_robot(nav_state, xy) -> None:
    nav_state.set(
        "robot_pose", Odometry(Header(3.0, "map"), "base_footprint", Pose.from_xy_yaw(*xy, 0.0))
    )


def diagnostic(nav_state) -> DiagnosticStatus:
    status = nav_state.get("diagnostics.path", DiagnosticStatus)
    assert status.hardware_id == "planner"
    return status


def test_plans_through_the_door_and_keeps_the_plan_while_it_is_good():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 1.5))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert path.header.frame_id == "map" and path.header.stamp == 7.0
    xy_yaw = path.as_xy_yaw()
    assert xy_yaw[0, :2].tolist() == [1.0, 1.0]
    assert xy_yaw[-1].tolist() == pytest.approx([7.0, 1.0, 1.5])
    assert xy_yaw[:, 1].max() > 2.4  # through the door
    assert planner.planner.checker(room()).polyline_free(xy_yaw[:, :2])[0]
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.OK and "goal (7.00, 1.00)" in status.message
    # The robot moves along the path: same plan, no new search.
    set_robot(nav_state, tuple(xy_yaw[len(xy_yaw) // 3, :2]))
    planner.update(nav_state)
    assert nav_state.get("path", Path) is path and planner.plan_count == 1


def test_replans_when_the_path_ahead_is_blocked_or_the_robot_strays():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0))
    planner.update(nav_state)
    first = nav_state.get("path", Path)
    # An obstacle appears on the path ahead (a new costmap, as a maps manager would store).
    blocked = room()
    x, y = first.as_xy_yaw()[len(first) // 2, :2]
    ix, iy = blocked.world_to_cell(x, y)
    blocked.data[int(iy) - 2 : int(iy) + 3, int(ix) - 2 : int(ix) + 3] = 254
    nav_state.set("map", blocked)
    planner.update(nav_state)
    second = nav_state.get("path", Path)
    assert planner.plan_count == 2 and second is not first and len(second) > 0
    assert planner.planner.checker(blocked).polyline_free(second.as_xy_yaw()[:, :2])[0]
    # The robot is pushed 1 m off the path: plan again from where it is.
    set_robot(nav_state, (1.0, 2.2))
    planner.update(nav_state)
    third = nav_state.get("path", Path)
    assert planner.plan_count == 3 and third.as_xy_yaw()[0, :2].tolist() == [1.0, 2.2]


def test_a_plan_is_kept_while_half_the_clearance_is_and_dropped_when_it_is_not():
    # Planned with 0.1 m of clearance beyond the 0.25 m body, kept while the body and half the
    # clearance fit: a wall growing into the clearance (noisy cells narrowing a passage) does
    # not drop it. (The shortest path, not centred: it passes close to the door's post.)
    planner = make_planner({"preferred_clearance": 0.0})
    nav_state = state_with((7.0, 1.0, 0.0))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    xy = path.as_xy_yaw()[:, :2]
    door = xy[np.argmin(np.abs(xy[:, 0] - 4.05))]  # where the path crosses the wall's line
    narrowed = room()
    # Cells 0.38-0.43 m above the path at the door: within the footprint (0.35 m, the test
    # conservative by half a cell diagonal), outside the body and half the clearance (0.30 m).
    ix, iy = (int(v) for v in narrowed.world_to_cell(door[0], door[1] + 0.43))
    narrowed.data[iy, ix - 3 : ix + 4] = 254
    nav_state.set("map", narrowed)
    keep, footprint = planner.planner.keep_checker(narrowed), planner.planner.checker(narrowed)
    assert not footprint.polyline_free(xy)[0] and keep.polyline_free(xy)[0]
    planner.update(nav_state)
    assert nav_state.get("path", Path) is path and planner.plan_count == 1
    # A cell beside the path, clear of the body but within half the clearance (0.28-0.35 m
    # away, whichever cell lands there): a new plan.
    k = len(xy) // 4
    tangent = (xy[k + 1] - xy[k - 1]) / np.hypot(*(xy[k + 1] - xy[k - 1]))
    normal = np.array([-tangent[1], tangent[0]])
    for offset in np.arange(0.28, 0.36, 0.01):
        blocked = narrowed.copy()
        ix, iy = (int(v) for v in blocked.world_to_cell(*(xy[k] - offset * normal)))
        blocked.data[iy, ix] = 254
        ompl = planner.planner
        if (ompl.body_checker(blocked).polyline_free(xy)[0]
                and not ompl.keep_checker(blocked).polyline_free(xy)[0]):
            break
    else:
        pytest.fail("no cell beside the path between the body and half the clearance")
    nav_state.set("map", blocked)
    planner.update(nav_state)
    assert planner.plan_count == 2 and nav_state.get("path", Path) is not path


def test_a_plan_that_starts_with_an_escape_is_kept():
    planner = make_planner()
    # 0.3 m from the wall at x = 4: inside the 0.25 + 0.1 m footprint, the body clear.
    nav_state = state_with((1.0, 1.0, 0.0), robot_xy=(3.65, 1.0))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert len(path) > 0 and path.as_xy_yaw()[0, :2].tolist() == [3.65, 1.0]
    planner.update(nav_state)
    assert nav_state.get("path", Path) is path and planner.plan_count == 1


def test_a_goal_inside_the_clearance_of_the_current_map_is_approached_and_the_plan_kept():
    planner = make_planner()
    # In the cell centred 0.30 m from the wall's cell centres (x = 4.025), less half a cell
    # diagonal (the checker's rule): inside the 0.25 + 0.1 m footprint and inside the body +
    # half the clearance a plan is kept with, the 0.25 m body clear.
    nav_state = state_with((3.72, 1.0, 0.0))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    assert len(path) > 0 and path.as_xy_yaw()[-1].tolist() == pytest.approx([3.72, 1.0, 0.0])
    keep = planner.planner.keep_checker(room())
    assert not keep.polyline_free(path.as_xy_yaw()[:, :2])[0]
    planner.update(nav_state)
    assert nav_state.get("path", Path) is path and planner.plan_count == 1
    set_robot(nav_state, (3.72, 1.0))  # at the goal, on the approach: still kept
    planner.update(nav_state)
    assert nav_state.get("path", Path) is path and planner.plan_count == 1
    # An obstacle that the body would touch at the goal drops the plan: the goal is impossible.
    blocked = room()
    blocked.data[20, 77] = 254  # the cell centred at (3.875, 1.025)
    nav_state.set("map", blocked)
    planner.update(nav_state)
    assert planner.plan_count == 2 and len(nav_state.get("path", Path)) == 0
    assert "goal (3.72, 1.00) is closer than" in diagnostic(nav_state).message
    # The same goal too close to a wall of the static map is the goal's fault: rejected.
    strict = make_planner()
    nav_state = state_with((3.72, 1.0, 0.0))
    nav_state.set("map.base", room())
    strict.update(nav_state)
    assert "goal (3.72, 1.00) is closer than" in strict.take_goal_rejection()


def test_a_plan_without_an_approach_is_kept_at_its_end_with_half_the_clearance_only():
    # Poses 0.3 m apart: at the goal, the robot is nearest the last pose alone.
    planner = make_planner({"interpolation_step": 0.3})
    nav_state = state_with((7.0, 1.0, 0.0))
    planner.update(nav_state)
    path = nav_state.get("path", Path)
    set_robot(nav_state, (7.0, 1.0))  # at the goal
    planner.update(nav_state)
    assert nav_state.get("path", Path) is path and planner.plan_count == 1
    # A cell centred 0.30 m from the goal's cell centre: the body clear there, half the
    # clearance not. The robot at the end of the plan does not keep it.
    narrowed = room()
    narrowed.data[26, 140] = 254
    nav_state.set("map", narrowed)
    planner.update(nav_state)
    assert planner.plan_count == 2


def test_an_unreachable_goal_gives_an_empty_path_and_a_warning():
    world = room()
    world.data[:, 80:82] = 254  # close the door
    planner = make_planner({"solve_time": 0.2})
    nav_state = state_with((7.0, 1.0, 0.0), world=world)
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    status = diagnostic(nav_state)
    assert status.level == DiagnosticLevel.WARN
    assert "goal (7.00, 1.00) is unreachable from (1.00, 1.00)" in status.message
    assert planner.take_goal_rejection() is None  # blocked for now: the recovery decides


def test_a_goal_impossible_on_the_static_map_is_rejected():
    planner = make_planner()
    nav_state = state_with((4.05, 1.0, 0.0))
    nav_state.set("map.base", room())
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert "goal (4.05, 1.00) is inside an obstacle" in planner.take_goal_rejection()
    other = state_with((1.0, 1.0, 0.0), frame="odom")
    planner.update(other)
    assert "is in frame 'odom'" in planner.take_goal_rejection()


def test_takes_a_simple_map_and_reports_a_missing_map_or_pose():
    world = SimpleMap(160, 80, 0.05)
    world.cells[0:48, 80:82] = True
    planner = make_planner({"state_space": "ReedsShepp", "turning_radius": 0.4})
    nav_state = state_with((7.0, 1.0, 0.0), world=world)
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) > 0
    empty = NavState()
    empty.set("goals", nav_state.get("goals", Goals))
    planner.update(empty)
    assert "no robot_pose yet" in diagnostic(empty).message
    set_robot(empty, (1.0, 1.0))
    planner.update(empty)
    assert "no map yet" in diagnostic(empty).message
    empty.set("map", "not a map")
    planner.update(empty)
    assert "holds a str, not a Costmap2D" in diagnostic(empty).message


def test_no_goal_gives_an_empty_path_and_idle():
    planner = make_planner()
    nav_state = state_with((7.0, 1.0, 0.0))
    nav_state.set("goals", Goals(Header(5.0, "map"), []))
    planner.update(nav_state)
    assert len(nav_state.get("path", Path)) == 0
    assert diagnostic(nav_state).message == "idle: no goal"


def test_the_robot_geometry_radius_is_the_footprint():
    planner = make_planner({"clearance_distance": 0.0}, geometry=RobotGeometry(radius=0.6))
    assert planner.planner.footprint_radius == pytest.approx(0.6)
    nav_state = state_with((7.0, 1.0, 0.0))
    planner.update(nav_state)
    # A 1.2 m wide robot still passes the 1.6 m door, keeping 0.6 m from every wall cell.
    path = nav_state.get("path", Path).as_xy_yaw()
    centres = np.stack(room().cell_to_world(*np.nonzero(room().data.T >= 254)), axis=1)
    d = np.hypot(path[:, None, 0] - centres[None, :, 0], path[:, None, 1] - centres[None, :, 1])
    assert d.min() > 0.6


@pytest.mark.parametrize(
    ("params", "words"),
    [
        ({"planner": "Astar"}, "ompl.planner = 'Astar': must be one of"),
        ({"state_space": "Dubins", "planner": "FMT"}, "FMT"),
        ({"solve_time": -1.0}, "ompl.solve_time"),
        ({"seed": -2}, "ompl.seed"),
        ({"turning_radius": math.nan}, "ompl.turning_radius"),
    ],
)
def test_bad_parameters_fail_the_configuration_naming_them(params, words):
    with pytest.raises(PluginConfigurationError, match=words.replace("(", r"\(")):
        make_planner(params)


def test_runtime_changes_rebuild_the_planner_and_refuse_impossible_combinations():
    planner = make_planner()
    planner.apply_parameter("planner", planner.validate_parameter("planner", "FMT"))
    assert planner.planner.planner == "FMT"
    with pytest.raises(ParameterValueError, match="ompl.state_space: planner = 'FMT'"):
        planner.validate_parameter("state_space", "Dubins")
    planner.apply_parameter("planner", planner.validate_parameter("planner", "RRTConnect"))
    value = planner.validate_parameter("state_space", "ReedsShepp")
    planner.apply_parameter("state_space", value)
    assert planner.planner.state_space == "ReedsShepp"


def test_declarations_list_the_parameters_topics_and_keys():
    names = {p.name for p in OMPLPlanner.parameter_declarations()}
    assert {"state_space", "planner", "turning_radius", "solve_time", "seed", "freq"} <= names
    assert [str(k) for k in OMPLPlanner.READS] == ["goals", "robot_pose", "map", "map.base"]
    assert [str(k) for k in OMPLPlanner.WRITES] == ["path", "diagnostics.path"]


@pytest.mark.parametrize(
    ("name", "space"), [("ompl.params.yaml", "SE2"), ("ompl.reeds_shepp.params.yaml", "ReedsShepp")]
)
def test_the_shipped_params_files_configure_the_plugin(name, space):
    import yaml

    from easynav.core.plugins.discovery import load_plugin_class
    from easynav.core.plugins.plugin_kinds import PLANNER

    path = FilePath(__file__).resolve().parents[3] / "params" / name
    if not path.exists():
        pytest.skip("the repository's params/ is not here (the package is installed alone)")
    section = yaml.safe_load(path.read_text())["planner_node"]["ros__parameters"]
    (alias,) = section["planner_types"]
    settings = {k: v for k, v in section[alias].items() if k != "plugin"}
    assert section[alias]["plugin"] == "easynav_ompl_planner/OMPLPlanner"
    context = PluginContext(
        parameters=DictParameters({f"{alias}.{k}": v for k, v in settings.items()}),
        namespace=f"ompl_test_{next(_namespaces)}",
        now=lambda: 7.0,
    )
    plugin_class = load_plugin_class(PLANNER, section[alias]["plugin"], "plugin")
    assert plugin_class is OMPLPlanner  # the entry point is installed
    planner = OMPLPlanner()
    planner.initialize(context, alias)
    assert planner.planner.state_space == space and planner.planner.planner == "RRTConnect"


def test_ompl_over_a_gridmap_or_a_navmap_alone_is_refused_before_starting():
    # The matrix found it: a GridMap stack with OMPL started, and OMPL never planned ("NavState
    # 'map' holds a GridMap, not a Costmap2D"). Over a costmap or a SimpleMap it plans.
    from easynav.core.plugins.compatibility import compatibility_errors
    from easynav.maps.gridmap.gridmap_maps_manager import GridmapMapsManager
    from easynav.maps.navmap.navmap_maps_manager import NavMapMapsManager
    from easynav.maps.simple_maps_manager import SimpleMapsManager
    from easynav.planners.ompl_planner import OMPLPlanner

    ompl = ("ompl", "easynav_ompl_planner/OMPLPlanner", OMPLPlanner)
    for alias, name, cls, provides in (
        ("elevation", "easynav_gridmap_maps_manager/GridmapMapsManager", GridmapMapsManager,
         "gridmap"),
        ("mesh", "easynav_navmap_maps_manager/NavMapMapsManager", NavMapMapsManager, "navmap"),
    ):
        errors = compatibility_errors({"maps_manager_node": [(alias, name, cls)],
                                       "planner_node": [ompl]})
        assert errors == [
            "planner_node.ompl [easynav_ompl_planner/OMPLPlanner] needs a map of type costmap "
            f"or simple_map, but maps_manager_node.{alias} [{name}] provides {provides}"
        ]
    simple = ("simple", "easynav_simple_maps_manager/SimpleMapsManager", SimpleMapsManager)
    assert compatibility_errors({"maps_manager_node": [simple], "planner_node": [ompl]}) == []
