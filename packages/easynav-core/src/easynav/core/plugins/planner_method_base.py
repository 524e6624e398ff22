"""PlannerMethodBase: plugins that compute a path to the current goal."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins.method_base import MethodBase


class PlannerMethodBase(MethodBase):
    """A planner: ``update`` (non-RT, at ``freq`` or forced when ``goals`` changed) reads
    ``goals`` (plans to the first), ``robot_pose`` and a map key, and writes ``path``
    (an empty :class:`Path` means no plan).
    """

    HAS_UPDATE = True

    def update(self, nav_state: NavState) -> None:
        """Plan. Non-RT thread."""
        raise NotImplementedError

    def reject_goal(self, reason: str) -> None:
        """Declare the first goal impossible (off the map, inside a static obstacle, in a frame
        the planner cannot use): planner_node aborts the mission with ``reason``, which the
        goal client receives (NAVIGATION_FAILED). For a goal that is only blocked for now, leave
        an empty path instead: the recovery system decides. Non-RT thread, from ``update``.
        """
        self._goal_rejection = reason

    def take_goal_rejection(self) -> str | None:
        """The reason given to :meth:`reject_goal` since the last call, or None. planner_node."""
        reason = getattr(self, "_goal_rejection", None)
        self._goal_rejection = None
        return reason
