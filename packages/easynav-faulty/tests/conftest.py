"""Fixtures for running the Faulty plugins without ROS: a manual clock and a plugin factory."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import pytest

from easynav.core.plugins import DictParameters, MethodBase, PluginContext


class ManualClock:
    """A node clock the test moves by hand (seconds)."""

    def __init__(self, start: float = 100.0) -> None:
        self.t = start

    def __call__(self) -> float:
        return self.t

    def advance(self, dt: float) -> float:
        self.t += dt
        return self.t


@pytest.fixture
def clock() -> ManualClock:
    return ManualClock()


@pytest.fixture
def make_plugin(clock: ManualClock) -> Callable[..., Any]:
    """``make_plugin(cls, alias="faulty", **params)``: an initialised plugin on ``clock``.

    ``params`` are the plugin's own parameters, without the alias prefix.
    """

    def make(cls: type[MethodBase], alias: str = "faulty", **params: Any) -> Any:
        context = PluginContext(
            parameters=DictParameters({f"{alias}.{k}": v for k, v in params.items()}),
            now=clock,
            logger=logging.getLogger("easynav.faulty.tests"),
        )
        plugin = cls()
        plugin.initialize(context, alias)
        return plugin

    return make
