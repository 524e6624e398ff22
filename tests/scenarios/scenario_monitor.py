"""ScenarioMonitor: the demo's RunMonitor plus what the scenarios assert on (diagnostics,
mitigation reports, velocity commands).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import Log
from rclpy.qos import QoSProfile, ReliabilityPolicy

from easynav.playground.demo.run_monitor import RunMonitor
from easynav.system.ros.converters import time_from_msg


@dataclass(frozen=True)
class SeenDiagnostic:
    """One status of a ``diagnostics`` array, with the array's stamp (its publisher's simulated
    clock when it published)."""

    stamp: float
    name: str
    level: int  # diagnostic_msgs/DiagnosticStatus: OK 0, WARN 1, ERROR 2, STALE 3
    message: str
    hardware_id: str
    values: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class SeenReport:
    """One ``mitigation`` report (rcl_interfaces/Log) with its stamp."""

    stamp: float
    level: int
    message: str


class ScenarioMonitor(RunMonitor):
    """Everything :class:`RunMonitor` records (truth, estimates, collisions, goal manager info),
    plus:

    - :attr:`diagnostics`: every status of every ``/diagnostics`` array (DiagnosticRecoveryManager
      publishes NavState's ``diagnostics`` group there), in arrival order;
    - :attr:`reports`: every ``/mitigation`` report;
    - :attr:`commands`: ``(stamp, vx, wz)`` of every velocity command sent to the robot.

    Diagnostics and reports carry the stamp their publisher gave them (EasyNav's simulated
    clock when it published), commands the monitor's simulated clock at arrival. Only
    publisher stamps are comparable with the playground's record: on a loaded machine this
    process reads its messages late (seconds, when its queues are deep), so an arrival stamp
    says when the test looked, not when it happened. What reached the robot, and when, is in
    the playground's record (``ScenarioRun.commands_applied``).

    Thread contract: callbacks in the executor that spins it (the test's thread); read the
    lists from that thread, or under :attr:`lock`.
    """

    def __init__(self, path_topic: str | None = None, **kwargs) -> None:
        super().__init__(path_topic, **kwargs)
        self.diagnostics: list[SeenDiagnostic] = []
        self.reports: list[SeenReport] = []
        self.commands: list[tuple[float, float, float]] = []
        reliable = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        self.create_subscription(DiagnosticArray, "/diagnostics", self._on_diagnostics, reliable)
        self.create_subscription(Log, "/mitigation", self._on_report, reliable)

    def sim_now(self) -> float:
        """The simulated time (s) of this node's clock."""
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        now = time_from_msg(msg.header.stamp)
        seen = [
            SeenDiagnostic(
                now,
                s.name,
                int.from_bytes(s.level, "little") if isinstance(s.level, bytes) else int(s.level),
                s.message,
                s.hardware_id,
                {v.key: v.value for v in s.values},
            )
            for s in msg.status
        ]
        with self.lock:
            self.diagnostics.extend(seen)

    def _on_report(self, msg: Log) -> None:
        with self.lock:
            self.reports.append(SeenReport(time_from_msg(msg.stamp), int(msg.level), msg.msg))

    def _on_cmd(self, msg) -> None:
        # RunMonitor's cmd_vel / cmd_vel_stamped callback: keep the values too.
        super()._on_cmd(msg)
        twist = getattr(msg, "twist", msg)
        with self.lock:
            self.commands.append((self.sim_now(), twist.linear.x, twist.angular.z))

    # ------------------------------------------------------------------ queries
    def first_diagnostic(
        self, hardware_id: str, level: int, since: float = float("-inf")
    ) -> SeenDiagnostic | None:
        """The first status received with this hardware id and level (after ``since``)."""
        with self.lock:
            return next(
                (
                    d
                    for d in self.diagnostics
                    if d.hardware_id == hardware_id and d.level == level and d.stamp >= since
                ),
                None,
            )

    def latest_diagnostic(self, hardware_id: str) -> SeenDiagnostic | None:
        """The last status received with this hardware id."""
        with self.lock:
            return next(
                (d for d in reversed(self.diagnostics) if d.hardware_id == hardware_id), None
            )

    def report_messages(self) -> list[str]:
        """The mitigation reports' texts, in order."""
        with self.lock:
            return [r.message for r in self.reports]
