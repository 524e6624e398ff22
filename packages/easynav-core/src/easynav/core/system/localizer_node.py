"""LocalizerNode: hosts the localizer (RT prediction, non-RT correction)."""

from __future__ import annotations

from easynav.core.plugins.plugin_kinds import LOCALIZER
from easynav.core.system.component_node import ComponentNode
from easynav.core.types import Odometry


class LocalizerNode(ComponentNode):
    """localizer_node: ``localizer_types`` (at most one), ``<alias>.*``.

    A new localizer instance gets the valid ``robot_pose`` left in NavState by the previous one,
    of any type, through ``on_last_known_pose`` before its first cycle.

    Thread contract: ``cycle_rt`` in the RT thread, ``cycle`` in the non-RT thread.
    """

    KIND = LOCALIZER
    TYPES_PARAMETER = "localizer_types"
    MAX_PLUGINS = 1

    def __init__(self, namespace, system, **kwargs):
        super().__init__("localizer_node", namespace, system, **kwargs)

    def after_plugins_loaded(self) -> None:
        if not self.nav_state.has("robot_pose"):
            return
        pose = self.nav_state.get_safe("robot_pose", Odometry)
        if pose.is_finite():
            for lp in self.plugins:
                lp.plugin.on_last_known_pose(pose)

    def cycle_rt(self, trigger: bool) -> bool:
        """Predict when due or triggered; True when the localizer ran. RT thread."""
        if not self.active:
            return False
        return bool(self.run_scheduled(rt=True, force=trigger))

    def cycle(self) -> None:
        """Correct when due. Non-RT thread."""
        if self.active:
            self.run_scheduled(rt=False)
