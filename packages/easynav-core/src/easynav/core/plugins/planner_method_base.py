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
