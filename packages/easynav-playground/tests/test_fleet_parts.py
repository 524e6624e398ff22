"""The parts of the multi-robot demo that need no ROS: the world's robots, the fleet params."""

from __future__ import annotations

import pytest
import yaml

from easynav.playground.demo.demo import DEFAULT_PARAMS, build_parser, main
from easynav.playground.demo.params_patch import derive_fleet_params
from easynav.playground.world_description import WORLDS_DIR, WorldDescription, load_waypoints


def test_the_crossing_world_declares_two_robots_whose_paths_cross():
    description = WorldDescription.resolve("crossing")
    r1, r2 = description.fleet(2)
    assert (r1.name, r2.name) == ("r1", "r2")
    (g1,) = load_waypoints(r1.waypoints_path)
    (g2,) = load_waypoints(r2.waypoints_path)
    # r1 east along y = 2.0, r2 south along x = 3.0: the straight legs cross at (3.0, 2.0).
    assert r1.start_pose[1] == g1[1] == 2.0 and r1.start_pose[0] < 3.0 < g1[0]
    assert r2.start_pose[0] == g2[0] == 3.0 and g2[1] < 2.0 < r2.start_pose[1]
    with pytest.raises(ValueError, match="declares 2 robot"):
        description.fleet(3)
    with pytest.raises(ValueError, match="at least 2"):
        description.fleet(1)


@pytest.mark.parametrize(
    ("robots", "culprit"),
    [
        ({"name": "r1"}, "start_pose"),
        ({"name": "1r", "start_pose": [0, 0, 0]}, "name"),
        ({"name": "r1", "start_pose": [0, 0, 0], "speed": 1}, "keys among"),
        ([{"name": "r1", "start_pose": [1, 1, 0]}, {"name": "r1", "start_pose": [2, 1, 0]}],
         "unique"),
    ],
)
def test_bad_robots_sections_are_refused_naming_the_problem(tmp_path, robots, culprit):
    path = tmp_path / "w.yaml"
    path.write_text(yaml.safe_dump({
        "map": str(WORLDS_DIR / "crossing.map"),
        "robots": robots if isinstance(robots, list) else [robots],
    }))
    with pytest.raises(ValueError, match=culprit):
        WorldDescription.resolve(str(path))


def test_fleet_params_have_a_section_per_robot_with_its_prefix_start_and_relative_topics(
    tmp_path,
):
    out = tmp_path / "fleet.yaml"
    notes, paths = derive_fleet_params(
        DEFAULT_PARAMS, WORLDS_DIR / "crossing.map",
        [("r1", (1.5, 2.0, 0.0)), ("r2", (3.0, 6.0, -1.5708))], out,
    )
    document = yaml.safe_load(out.read_text())
    single = yaml.safe_load(DEFAULT_PARAMS.read_text())
    assert set(document) == {f"{r}/{node}" for r in ("r1", "r2") for node in single}
    for robot, x in (("r1", 1.5), ("r2", 3.0)):
        system = document[f"{robot}/system_node"]["ros__parameters"]
        assert system["tf_prefix"] == robot
        localizer = document[f"{robot}/localizer_node"]["ros__parameters"]
        assert localizer["simple"]["initial_pose"]["x"] == x
        sensors = document[f"{robot}/sensors_node"]["ros__parameters"]
        assert sensors["laser"]["topic"] == "scan"  # /scan in the single-robot file
        assert all(s["ros__parameters"]["use_sim_time"] for k, s in document.items())
    assert paths == {"r1": "/r1/planner_node/simple/path", "r2": "/r2/planner_node/simple/path"}
    assert any("tf_prefix" in note for note in notes)
    assert not list(tmp_path.glob("*.part.yaml"))
    # A file with namespaced sections already is refused (its robots are derived here).
    with pytest.raises(ValueError, match="namespaced"):
        derive_fleet_params(out, WORLDS_DIR / "crossing.map", [("r1", (1.5, 2.0, 0.0))],
                            tmp_path / "again.yaml")


def test_demo_robots_option(capsys):
    assert build_parser().parse_args(["--robots", "2"]).robots == 2
    assert build_parser().parse_args([]).robots == 1
    assert main(["--robots", "0"]) == 2
    assert main(["--robots", "2", "--waypoints", "w.yaml"]) == 2
    assert main(["--robots", "3", "--world", "crossing"]) == 2  # it declares two
    err = capsys.readouterr().err
    assert ">= 1" in err and "--waypoints" in err and "declares 2 robot" in err


class _Publisher:
    def __init__(self, namespace: str, name: str) -> None:
        self.node_namespace, self.node_name = namespace, name


class _Graph:
    """What get_publishers_info_by_topic answers, topic by topic."""

    def __init__(self, publishers: dict[str, list[_Publisher]]) -> None:
        self.publishers = publishers

    def get_publishers_info_by_topic(self, topic: str) -> list[_Publisher]:
        return self.publishers.get(topic, [])


def test_the_topic_watch_names_a_foreign_publisher_and_skips_one_of_unknown_node():
    from easynav.playground.demo.fleet_demo import UNKNOWN_NODE, TopicWatch

    watch = TopicWatch()
    # A look while r2's EasyNav starts: the middleware knows its publishers, not their node.
    watch.look(_Graph({
        "/r2/cmd_vel": [_Publisher("/r2", "controller_node"), _Publisher("/", UNKNOWN_NODE)],
        "/r1/tf": [_Publisher("/", "playground"), _Publisher("/r1", "localizer_node")],
    }), ["r1", "r2"])
    assert watch.apart and watch.samples == 1
    # r1's controller publishing on r2's cmd_vel is a crossing, named.
    watch.look(_Graph({"/r2/cmd_vel": [_Publisher("/r1", "controller_node")]}), ["r1", "r2"])
    assert watch.crossings == ["/r2/cmd_vel published by /r1/controller_node"]
    assert not watch.apart
