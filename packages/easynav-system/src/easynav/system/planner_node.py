"""PlannerNode: hosts the planner and guards the path it produces."""

from __future__ import annotations

from easynav.core.diagnostics import write_diagnostic
from easynav.core.nav_state_keys import GOALS, PATH
from easynav.core.plugins.plugin_kinds import PLANNER
from easynav.core.types import DiagnosticLevel, DiagnosticStatus, Header, Path
from easynav.system.component_node import ComponentNode


class PlannerNode(ComponentNode):
    """planner_node: ``planner_types`` (at most one), ``<alias>.*``.

    The planner runs at its ``freq``, and at once when ``goals`` changed since its last run.
    A goal the planner rejects (``reject_goal``) ends the mission with the planner's reason.
    A path with a non-finite pose is discarded: ``path`` is left empty, so no controller follows
    it, and ``diagnostics.path`` is ERROR (hardware_id planner) until a finite path comes.

    Activating a planner that writes ``path`` (its ``WRITES``: every path planner; not the
    Dummy planner) sets ``path`` to an empty path: nothing is planned yet. A controller that
    drives to the first goal where no planner writes a path (VFF, as the original's) sees that
    a path will come and waits for it; without such a planner ``path`` is erased. Before, VFF
    drove straight at the first waypoint, into the wall between, while the non-RT thread was
    still busy with the OctoMap maps manager building its voxel map (5 s) and the planner had
    not yet run.

    Thread contract: ``cycle`` in the non-RT thread.
    """

    KIND = PLANNER
    TYPES_PARAMETER = "planner_types"
    MAX_PLUGINS = 1
    MONITOR_RT = False

    def __init__(self, namespace, system, **kwargs):
        super().__init__("planner_node", namespace, system, **kwargs)
        self._planned_goals = None
        self._path_rejected = False

    def on_activate(self, state):
        if any(PATH in lp.plugin.WRITES for lp in self.plugins):
            frame = self.system.services.tf_info().map_frame
            self.nav_state.set(PATH, Path(Header(self.now_seconds(), frame), []))
        elif self.nav_state.has(PATH):
            self.nav_state.erase(PATH)  # one from before a reconfiguration without a planner
        return super().on_activate(state)

    def cycle(self) -> None:
        """Plan when due or forced by new goals. Non-RT thread."""
        if not self.active:
            return
        goals = self.nav_state.get(GOALS) if self.nav_state.has(GOALS) else None
        force = goals is not self._planned_goals
        self._planned_goals = goals
        for lp, _ok in self.run_scheduled(rt=False, force=force):
            rejection = lp.plugin.take_goal_rejection()
            if rejection and goals is not None and len(goals) > 0:
                self.get_logger().warning(f"goal rejected by {lp.alias}: {rejection}")
                self.system.services.requests.post_abort(rejection)
            self._check_path(self.now_seconds())

    def _check_path(self, now: float) -> None:
        if not self.nav_state.has(PATH):
            return
        path = self.nav_state.get(PATH, Path)
        if path.is_finite():
            if self._path_rejected:
                self._path_rejected = False
                write_diagnostic(
                    self.nav_state,
                    "path",
                    DiagnosticStatus(DiagnosticLevel.OK, "path", "finite path", "planner"),
                )
            return
        self.nav_state.set(PATH, Path(Header(now, path.header.frame_id), []))
        if not self._path_rejected:
            self._path_rejected = True
            self.get_logger().error("the planner produced a path with a non-finite pose: discarded")
            write_diagnostic(
                self.nav_state,
                "path",
                DiagnosticStatus(
                    DiagnosticLevel.ERROR,
                    "path",
                    "path with a non-finite pose discarded",
                    "planner",
                ),
            )
