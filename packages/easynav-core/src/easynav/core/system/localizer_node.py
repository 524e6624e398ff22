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
        ran = False
        now = self.now_seconds()
        for lp in self.plugins:
            if lp.plugin.is_time_to_run_rt(now) or trigger:
                if trigger:
                    lp.plugin.rt_schedule.restart(now)
                self.run_plugin(lp, "update_rt")
                ran = True
                if lp.rt_monitor is not None:
                    lp.rt_monitor.record_run()
            self.check_rate(lp, lp.rt_monitor, now)
        return ran

    def cycle(self) -> None:
        """Correct when due. Non-RT thread."""
        if not self.active:
            return
        now = self.now_seconds()
        for lp in self.plugins:
            if lp.plugin.is_time_to_run(now):
                self.run_plugin(lp, "update")
                if lp.monitor is not None:
                    lp.monitor.record_run()
            self.check_rate(lp, lp.monitor, now)
