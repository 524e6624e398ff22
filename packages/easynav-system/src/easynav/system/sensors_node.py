"""SensorsNode: turns the robot's sensor topics into perceptions in NavState."""

from __future__ import annotations

from easynav.system.component_node import ComponentNode
from easynav.system.sensors import SensorsManager


class SensorsNode(ComponentNode):
    """sensors_node: ``forget_time``, ``sensors`` and per sensor ``topic``, ``type``, ``group``,
    ``plugin`` (see easynav.common.sensors). Its subscriptions are spun by the RT loop.

    Thread contract: ``cycle_rt`` in the RT thread (also the sensor callbacks), ``cycle`` in the
    non-RT thread.
    """

    MONITOR_RT = False
    MONITOR_NON_RT = False

    def __init__(self, namespace, system, **kwargs):
        super().__init__("sensors_node", namespace, system, **kwargs)
        self.manager: SensorsManager | None = None

    def load_plugins(self) -> None:
        # Perception handlers are chosen per sensor by the manager, not listed as plugins.
        self.manager = SensorsManager()
        self.manager.configure(self.params, self, self.nav_state)

    def cleanup_node(self) -> None:
        if self.manager is not None:
            self.manager.cleanup()
            self.manager = None

    def new_data_pending(self) -> bool:
        """True when a sensor callback stored data the RT cycle has not consumed. RT thread."""
        manager = self.manager
        return manager is not None and self.active and manager.has_new_data()

    def cycle_rt(self) -> bool:
        """Expire old perceptions; True when new data arrived. RT thread."""
        if not self.active or self.manager is None:
            return False
        return self.manager.cycle_rt(self.now_seconds())

    def cycle(self) -> None:
        """Diagnostics and the fused perception cloud. Non-RT thread."""
        if not self.active or self.manager is None:
            return
        self.manager.cycle(self.now_seconds())
