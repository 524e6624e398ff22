"""ActivationAwareSchedule: a RateSchedule that tells its plugin when EasyNav was activated."""

from __future__ import annotations

from collections.abc import Callable

from easynav.core.plugins import RateSchedule


class ActivationAwareSchedule(RateSchedule):
    """A :class:`RateSchedule` that calls ``on_reset()`` whenever it is reset.

    ``RecoveryManagerBase`` has no activation hook, but the host node resets every plugin's
    schedules when it activates (so components start measuring afresh). Installing this as the
    manager's ``schedule`` turns that reset into an activation notice: the recovery systems
    restart their watches (sensor timeout, rate monitors) instead of counting the time EasyNav
    was inactive.

    Thread contract: ``reset`` runs in the thread that activates (no loop cycles the plugin
    then); ``on_reset`` must only set flags that the loops read later.
    """

    __slots__ = ("_on_reset",)

    def __init__(self, freq: float, on_reset: Callable[[], None]) -> None:
        super().__init__(freq)
        self._on_reset = on_reset

    def reset(self) -> None:
        super().reset()
        self._on_reset()
