"""RosGraphEvaluator (easynav_diagnostic_recovery/RosGraphEvaluator): EasyNav wired in ROS."""

from __future__ import annotations

import time
from typing import Any

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase
from easynav.recovery.diagnostic.evaluators import ros_graph_check as graph_check


class RosGraphEvaluator(EvaluatorBase):
    """hardware_id ``ros_graph``: ERROR when EasyNav is miswired in the ROS graph.

    On activation it discovers the subscriptions and velocity outputs (Twist / TwistStamped
    topics) of the EasyNav nodes in its own namespace, their plugins' included. Each run it
    checks them against the graph: ERROR when a discovered subscription has no publisher of its
    type (topics in ``ignored_topics`` are optional inputs and left out), or when no velocity
    output has a subscriber outside EasyNav (nodes in ``ignored_consumers``, monitoring tools,
    do not count). Nodes on simulated time whose ``/clock`` has no publisher are reported as one
    cause. Two margins keep it from firing too early (WARN meanwhile): ``startup_grace`` seconds
    after activation and ``error_debounce`` seconds of a persisting problem, both in wall time
    (steady clock), as the graph changes in wall time whatever the node's clock says. The ERROR
    does not depend on an active goal: it is meant for ShutdownRecovery. OK reports the consumed
    velocity topic and whether it is stamped.

    Thread contract: as :class:`EvaluatorBase`; ``on_activate`` and ``update`` both run in the
    non-RT thread (the manager calls ``on_activate`` at its first run after an activation).
    Exceptions: graph queries that fail are reported as missing nodes, never raised.
    """

    HARDWARE_ID = "ros_graph"
    PARAMETERS = (
        Param(
            "ignored_topics",
            ["goal_pose", "initialpose", "incoming_map", "incoming_occ_map", "incoming_pc2_map"],
            "optional inputs left out of the check (exact topic or trailing path)",
        ),
        Param(
            "ignored_consumers",
            ["easynav_tui_*", "_ros2cli*"],
            "nodes whose subscription to cmd_vel does not count (trailing * = prefix)",
        ),
        Param("startup_grace", 15.0, "seconds after activation with problems only WARN", "s",
              ge=0.0),
        Param("error_debounce", 2.0, "seconds a problem persists before ERROR", "s", ge=0.0),
    )

    def __init__(self) -> None:
        super().__init__()
        self.graph: Any = None
        self.namespace = "/"
        self.topology: graph_check.Topology | None = None
        self._activated_at = 0.0
        self._problem_since: float | None = None
        self.wall_clock = time.monotonic

    def on_initialize(self) -> None:
        self.graph = self.context.node
        self.namespace = self.context.namespace or "/"
        if not self.namespace.startswith("/"):
            self.namespace = "/" + self.namespace
        self.topology = None

    def on_activate(self) -> None:
        """Discover EasyNav's topology (every EasyNav node is configured by now)."""
        self._problem_since = None
        self._activated_at = self.wall_clock()
        if self.graph is None:
            self.topology = None
            return
        self.topology = graph_check.discover(
            self.graph, self.namespace, list(self.params.ignored_topics)
        )
        missing = self.topology.missing_nodes
        self.logger.info(
            f"{self.plugin_name}: discovered {len(self.topology.subscriptions)} subscriptions and "
            f"{len(self.topology.velocity_outputs)} velocity outputs in "
            f"{len(graph_check.EASYNAV_NODES) - len(missing)} EasyNav nodes"
            + (f" (missing: {', '.join(missing)})" if missing else "")
        )

    def on_deactivate(self) -> None:
        self.topology = None
        self._problem_since = None

    def update(self, nav_state: NavState) -> None:
        topology = self.topology
        if topology is None:
            self.publish_diagnostic(
                nav_state, DiagnosticLevel.WARN,
                "ROS graph topology not discovered yet (node not activated)",
            )
            return
        report = graph_check.check(self.graph, topology, list(self.params.ignored_consumers))
        problems = graph_check.problems_of(topology, report, self.plugin_name, self.namespace)
        values: dict[str, str] = {}
        if report.consumed_topic:
            stamped = report.consumed_type == graph_check.TWIST_STAMPED
            values["velocity_topic"] = report.consumed_topic
            values["velocity_type"] = "stamped" if stamped else "unstamped"
        if not problems:
            self._problem_since = None
            self.publish_diagnostic(
                nav_state, DiagnosticLevel.OK,
                f"velocity: {report.consumed_topic} [{values['velocity_type']}]", values,
            )
            return
        values["unfed_subscriptions"] = str(len(report.unfed))
        for i, sub in enumerate(report.unfed):
            values[f"unfed.{i}"] = f"{sub.topic} [{sub.type}] <- {sub.node}"
        if topology.missing_nodes:
            values["missing_nodes"] = ", ".join(topology.missing_nodes)
        now = self.wall_clock()
        if self._problem_since is None:
            self._problem_since = now
        message = "\n".join(problems)
        if now - self._activated_at < self.params.startup_grace:
            level, message = DiagnosticLevel.WARN, "(startup grace) " + message
        elif now - self._problem_since < self.params.error_debounce:
            level = DiagnosticLevel.WARN
        else:
            level = DiagnosticLevel.ERROR
        self.publish_diagnostic(nav_state, level, message, values)
