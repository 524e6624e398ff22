"""The ROS-graph check of RosGraphEvaluator as plain logic over a graph view (testable without ROS).

EasyNav's side of the graph (its nodes' subscriptions and velocity outputs) is discovered once,
on activation; every cycle then checks that topology against the current graph: a subscription
nobody feeds means EasyNav waits for data that never comes; a velocity output nobody outside
EasyNav consumes means nothing drives the robot.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
CLOCK = "rosgraph_msgs/msg/Clock"

#: The fixed names EasyNav gives its nodes; all share system_node's namespace.
EASYNAV_NODES = (
    "system_node",
    "controller_node",
    "localizer_node",
    "maps_manager_node",
    "planner_node",
    "sensors_node",
    "recovery_node",
)


class GraphView(Protocol):
    """What the check needs of the ROS graph (an rclpy Node provides exactly these calls)."""

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]: ...

    def get_subscriber_names_and_types_by_node(
        self, node_name: str, node_namespace: str
    ) -> list[tuple[str, list[str]]]: ...

    def get_publisher_names_and_types_by_node(
        self, node_name: str, node_namespace: str
    ) -> list[tuple[str, list[str]]]: ...

    def get_publishers_info_by_topic(self, topic_name: str) -> list: ...

    def get_subscriptions_info_by_topic(self, topic_name: str) -> list: ...


@dataclass(frozen=True)
class Subscription:
    """A subscription made by an EasyNav node (its plugins' included)."""

    node: str
    topic: str
    type: str


@dataclass
class Topology:
    """EasyNav's side of the graph, discovered on activation."""

    easynav_nodes: set[tuple[str, str]] = field(default_factory=set)
    subscriptions: list[Subscription] = field(default_factory=list)
    velocity_outputs: list[tuple[str, str]] = field(default_factory=list)
    missing_nodes: list[str] = field(default_factory=list)


@dataclass
class GraphReport:
    """The topology checked against the current graph."""

    unfed: list[Subscription] = field(default_factory=list)
    consumed_topic: str = ""
    consumed_type: str = ""


def fully_qualified(name: str, namespace: str) -> str:
    """``/ns/name`` from a node name and its namespace."""
    return f"{namespace}{name}" if namespace.endswith("/") else f"{namespace}/{name}"


def short_type(type_name: str) -> str:
    """``nav_msgs/msg/Odometry`` -> ``nav_msgs/Odometry``."""
    return type_name.replace("/msg/", "/", 1)


def topic_is_ignored(topic: str, ignored: list[str]) -> bool:
    """An entry matches a fully-qualified topic exactly, or its trailing path component(s)."""
    for entry in ignored:
        if not entry:
            continue
        suffix = entry if entry.startswith("/") else "/" + entry
        if topic == entry or topic.endswith(suffix):
            return True
    return False


def consumer_is_ignored(node_name: str, ignored: list[str]) -> bool:
    """A monitoring tool's node (``_ros2cli*``: a trailing ``*`` matches a name prefix)."""
    for entry in ignored:
        if entry.endswith("*") and node_name.startswith(entry[:-1]):
            return True
        if node_name == entry:
            return True
    return False


def discover(graph: GraphView, namespace: str, ignored_topics: list[str]) -> Topology:
    """EasyNav's topology in ``namespace``: every node's subscriptions and Twist outputs.

    Runs after every EasyNav node is configured (system_node configures all before activating
    any), so every plugin's subscriptions and publishers exist already.
    """
    topology = Topology(easynav_nodes={(name, namespace) for name in EASYNAV_NODES})
    present = set(graph.get_node_names_and_namespaces())
    for name in EASYNAV_NODES:
        fq_name = fully_qualified(name, namespace)
        if (name, namespace) not in present:
            topology.missing_nodes.append(fq_name)
            continue
        try:
            subscriptions = graph.get_subscriber_names_and_types_by_node(name, namespace)
            publications = graph.get_publisher_names_and_types_by_node(name, namespace)
        except Exception:  # the node vanished between listing the graph and asking about it
            topology.missing_nodes.append(fq_name)
            continue
        for topic, types in subscriptions:
            if topic_is_ignored(topic, ignored_topics):
                continue
            topology.subscriptions.extend(Subscription(fq_name, topic, t) for t in types)
        for topic, types in publications:
            topology.velocity_outputs.extend(
                (topic, t) for t in types if t in (TWIST, TWIST_STAMPED)
            )
    return topology


def check(graph: GraphView, topology: Topology, ignored_consumers: list[str]) -> GraphReport:
    """Which discovered subscriptions have no publisher of their type, and which velocity output
    (if any) a node outside EasyNav consumes (monitoring tools in ``ignored_consumers`` and
    EasyNav's own nodes do not count)."""
    report = GraphReport()
    for sub in topology.subscriptions:
        publishers = graph.get_publishers_info_by_topic(sub.topic)
        if not any(info.topic_type == sub.type for info in publishers):
            report.unfed.append(sub)
    for topic, type_name in topology.velocity_outputs:
        for info in graph.get_subscriptions_info_by_topic(topic):
            if info.topic_type != type_name:
                continue
            if (info.node_name, info.node_namespace) in topology.easynav_nodes:
                continue
            if consumer_is_ignored(info.node_name, ignored_consumers):
                continue
            report.consumed_topic, report.consumed_type = topic, type_name
            return report
    return report


def problems_of(topology: Topology, report: GraphReport, plugin_name: str, namespace: str):
    """The problems in words (empty when the wiring is sound)."""
    problems = []
    if not topology.velocity_outputs:
        problems.append("no velocity output: system_node has no cmd_vel publisher")
    elif not report.consumed_topic:
        outputs = ", ".join(f"{t} [{short_type(k)}]" for t, k in topology.velocity_outputs)
        problems.append(
            f"no subscriber for velocity output {outputs} (driver/simulator down, wrong topic, "
            f"or use_cmd_vel_stamped mismatch?)"
        )
    # /clock is subscribed by every node on simulated time: one cause, not one entry per node.
    unfed = [s for s in report.unfed if s.type != CLOCK]
    if len(unfed) < len(report.unfed):
        problems.append("use_sim_time is set but /clock is not published (simulator down?)")
    if unfed:
        lines = [f"  {s.topic} [{short_type(s.type)}], needed by {s.node}" for s in unfed]
        entries = ", ".join(f'"{relative_topic(s.topic, namespace)}"' for s in unfed)
        lines.append(f"  if optional, add to {plugin_name}.ignored_topics: {entries}")
        problems.append("no publisher for:\n" + "\n".join(lines))
    return problems


def relative_topic(topic: str, namespace: str) -> str:
    """The ``ignored_topics`` entry for ``topic``: relative to EasyNav's namespace, so it also
    works for another EasyNav instance in another namespace."""
    prefix = "/" if namespace == "/" else namespace + "/"
    return topic[len(prefix):] if topic.startswith(prefix) else topic
