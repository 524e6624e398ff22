"""RosGraphEvaluator: its check over a scripted graph (no ROS), then over a real ROS graph."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from recovery_harness import Clock, RecordingActions, make_context

from easynav.core.nav_state import NavState
from easynav.core.types import DiagnosticLevel
from easynav.recovery.diagnostic.evaluators import RosGraphEvaluator
from easynav.recovery.diagnostic.evaluators.ros_graph_check import TWIST, TWIST_STAMPED

OK, WARN, ERROR = DiagnosticLevel.OK, DiagnosticLevel.WARN, DiagnosticLevel.ERROR
ODOM = "nav_msgs/msg/Odometry"
SCAN = "sensor_msgs/msg/LaserScan"
CLOCK = "rosgraph_msgs/msg/Clock"


@dataclass
class Endpoint:
    node_name: str
    node_namespace: str
    topic_type: str


class ScriptedGraph:
    """A ROS graph: nodes with their publications and subscriptions."""

    def __init__(self) -> None:
        self.pubs: dict[tuple[str, str], dict[str, str]] = {}
        self.subs: dict[tuple[str, str], dict[str, str]] = {}

    def node(self, name, ns="/", pubs=None, subs=None):
        self.pubs[(name, ns)] = dict(pubs or {})
        self.subs[(name, ns)] = dict(subs or {})
        return self

    def get_node_names_and_namespaces(self):
        return list(self.pubs)

    def get_subscriber_names_and_types_by_node(self, name, ns):
        return [(t, [k]) for t, k in self.subs[(name, ns)].items()]

    def get_publisher_names_and_types_by_node(self, name, ns):
        return [(t, [k]) for t, k in self.pubs[(name, ns)].items()]

    def get_publishers_info_by_topic(self, topic):
        return [Endpoint(n, ns, t[topic]) for (n, ns), t in self.pubs.items() if topic in t]

    def get_subscriptions_info_by_topic(self, topic):
        return [Endpoint(n, ns, t[topic]) for (n, ns), t in self.subs.items() if topic in t]


def easynav(graph: ScriptedGraph, stamped=False, clock=False) -> ScriptedGraph:
    extra = {"/clock": CLOCK} if clock else {}
    graph.node("system_node", pubs={"/cmd_vel": TWIST_STAMPED if stamped else TWIST},
               subs={"/goal_pose": "geometry_msgs/msg/PoseStamped", **extra})
    graph.node("controller_node", subs=extra)
    graph.node("localizer_node", subs={"/odom": ODOM, "/initialpose": "x/msg/Y", **extra})
    for name in ("maps_manager_node", "planner_node", "recovery_node"):
        graph.node(name, subs=extra)
    graph.node("sensors_node", subs={"/scan": SCAN, **extra})
    return graph


class Bench:
    def __init__(self, graph, params=None) -> None:
        self.nav_state = NavState()
        self.clock = Clock()
        alias = "recovery_manager.ros_graph"
        context = make_context(
            {f"{alias}.{k}": v for k, v in (params or {}).items()},
            self.clock, RecordingActions(self.nav_state),
        )
        self.evaluator = RosGraphEvaluator()
        self.evaluator.initialize(context, alias)
        self.wall = 100.0
        self.evaluator.wall_clock = lambda: self.wall
        self.evaluator.graph = graph
        self.evaluator.namespace = "/"
        self.key = f"diagnostics.{alias}"

    def activate(self):
        self.evaluator.on_activate()

    def run(self, after: float = 0.0):
        self.wall += after
        self.evaluator.update(self.nav_state)
        return self.nav_state.get(self.key)


def test_a_well_wired_easynav_is_ok_and_names_its_velocity_topic():
    graph = easynav(ScriptedGraph())
    graph.node("driver", pubs={"/odom": ODOM, "/scan": SCAN}, subs={"/cmd_vel": TWIST})
    bench = Bench(graph)
    bench.activate()
    status = bench.run()
    assert status.level == OK and status.hardware_id == "ros_graph"
    assert status.message == "velocity: /cmd_vel [unstamped]"
    assert status.values["velocity_topic"] == "/cmd_vel"


def test_a_sensor_nobody_publishes_warns_during_the_grace_then_is_an_error():
    graph = easynav(ScriptedGraph())
    graph.node("driver", pubs={"/odom": ODOM}, subs={"/cmd_vel": TWIST})  # no /scan
    bench = Bench(graph, {"startup_grace": 15.0, "error_debounce": 2.0})
    bench.activate()
    status = bench.run()
    assert status.level == WARN and status.message.startswith("(startup grace)")
    assert "/scan [sensor_msgs/LaserScan], needed by /sensors_node" in status.message
    assert 'recovery_manager.ros_graph.ignored_topics: "scan"' in status.message
    assert bench.run(after=15.0).level == ERROR  # the problem has lasted beyond the debounce


def test_a_problem_must_persist_for_the_debounce_before_it_is_an_error():
    graph = easynav(ScriptedGraph())
    bench = Bench(graph, {"startup_grace": 0.0, "error_debounce": 2.0})
    bench.activate()
    status = bench.run()
    assert status.level == WARN
    assert "no subscriber for velocity output /cmd_vel [geometry_msgs/Twist]" in status.message
    assert bench.run(after=1.0).level == WARN
    assert bench.run(after=1.5).level == ERROR


def test_a_monitoring_tool_is_not_a_consumer_and_a_stamped_mismatch_is_not_either():
    graph = easynav(ScriptedGraph(), stamped=True)
    graph.node("_ros2cli_1234", subs={"/cmd_vel": TWIST_STAMPED})
    graph.node("driver", pubs={"/odom": ODOM, "/scan": SCAN}, subs={"/cmd_vel": TWIST})
    bench = Bench(graph, {"startup_grace": 0.0, "error_debounce": 0.0})
    bench.activate()
    status = bench.run()
    assert status.level == ERROR and "use_cmd_vel_stamped mismatch" in status.message


def test_an_unpublished_clock_is_one_cause_not_one_per_node():
    graph = easynav(ScriptedGraph(), clock=True)
    graph.node("driver", pubs={"/odom": ODOM, "/scan": SCAN}, subs={"/cmd_vel": TWIST})
    bench = Bench(graph, {"startup_grace": 0.0, "error_debounce": 0.0})
    bench.activate()
    status = bench.run()
    assert status.message == "use_sim_time is set but /clock is not published (simulator down?)"


def test_missing_easynav_nodes_are_listed_and_ignored_topics_left_out():
    graph = ScriptedGraph().node("system_node", pubs={"/cmd_vel": TWIST})
    graph.node("sensors_node", subs={"/scan": SCAN})
    graph.node("driver", subs={"/cmd_vel": TWIST})
    bench = Bench(graph, {"ignored_topics": ["scan"], "startup_grace": 0.0})
    bench.activate()
    assert bench.evaluator.topology.subscriptions == []
    assert "/controller_node" in bench.evaluator.topology.missing_nodes
    assert bench.run().level == OK


def test_before_activation_the_topology_is_unknown():
    bench = Bench(ScriptedGraph())
    status = bench.run()
    assert status.level == WARN and "not discovered yet" in status.message


@pytest.mark.ros
def test_over_a_real_ros_graph(ros):
    """Real rclpy nodes named like EasyNav's: an unfed subscription, then a driver appears."""
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry

    ns = "/rg_test"
    nodes = {name: ros.create_node(name, namespace=ns) for name in (
        "system_node", "controller_node", "localizer_node", "maps_manager_node",
        "planner_node", "sensors_node", "recovery_node",
    )}
    nodes["system_node"].create_publisher(Twist, "cmd_vel", 10)
    nodes["localizer_node"].create_subscription(Odometry, "odom", lambda m: None, 10)
    bench = Bench(nodes["recovery_node"], {"startup_grace": 0.0, "error_debounce": 0.0})
    bench.evaluator.namespace = ns
    assert ros.spin_until(lambda: len(nodes["recovery_node"].get_publishers_info_by_topic(
        f"{ns}/cmd_vel")) == 1 and len(nodes["recovery_node"].get_subscriptions_info_by_topic(
        f"{ns}/odom")) == 1, timeout=10.0)
    bench.activate()
    status = bench.run()
    assert status.level == ERROR
    assert f"{ns}/odom [nav_msgs/Odometry], needed by {ns}/localizer_node" in status.message
    driver = ros.create_node("base_driver", namespace=ns)
    driver.create_publisher(Odometry, "odom", 10)
    driver.create_subscription(Twist, "cmd_vel", lambda m: None, 10)
    assert ros.spin_until(lambda: bench.run().level == OK, timeout=10.0), bench.run().message
