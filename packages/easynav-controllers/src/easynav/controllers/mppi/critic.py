"""Critic: one scoring term of MPPI, a small plugin over the shared batch."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.core.plugins import Param


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [−π, π), element-wise (keeps the dtype)."""
    two_pi = angle.dtype.type(2.0 * np.pi) if isinstance(angle, np.ndarray) else 2.0 * np.pi
    half = two_pi / 2
    return np.remainder(angle + half, two_pi) - half


class Critic:
    """Base of the MPPI critics.

    A critic declares ``NAME`` (the name in the controller's ``critics`` list and the prefix of
    its parameters: ``<alias>.<NAME>.cost_weight``...) and ``PARAMETERS`` (its own, after the
    common ``enabled``, ``cost_weight``, ``cost_power``). :meth:`score` adds
    ``(cost_weight · term)^cost_power`` to ``batch.costs`` (or does nothing when the term does
    not apply this cycle). Parameters are read from the controller's values every cycle, so a
    runtime change takes effect at once.

    Thread contract: RT thread only. Exceptions: none for a well-formed batch.
    """

    NAME: ClassVar[str] = ""
    DEFAULT_WEIGHT: ClassVar[float] = 1.0
    PARAMETERS: ClassVar[tuple[Param, ...]] = ()

    def __init__(self, values: Mapping[str, Any]) -> None:
        self._values = values

    @classmethod
    def declarations(cls) -> tuple[Param, ...]:
        """Every parameter of this critic, relative to the controller's alias."""
        common = (
            Param("enabled", True, f"{cls.NAME}: add its term to the costs"),
            Param("cost_weight", cls.DEFAULT_WEIGHT, f"{cls.NAME}: weight", ge=0.0),
            Param("cost_power", 1, f"{cls.NAME}: exponent of the weighted term", ge=1),
        )
        own = common + cls.PARAMETERS
        return tuple(
            Param(f"{cls.NAME}.{p.name}", p.default, p.description, p.unit, p.type, p.gt, p.ge,
                  p.lt, p.le, p.choices, p.allow_nan, p.deprecated, p.dynamic)
            for p in own
        )

    def param(self, name: str) -> Any:
        """The current value of ``<NAME>.<name>``."""
        return self._values[f"{self.NAME}.{name}"]

    def score(self, batch: MppiBatch) -> None:
        """Add this critic's weighted term to ``batch.costs``."""
        if not self.param("enabled"):
            return
        term = self.compute(batch)
        if term is None:
            return
        weighted = self.param("cost_weight") * term
        power = self.param("cost_power")
        batch.costs += weighted if power == 1 else weighted**power

    def compute(self, batch: MppiBatch) -> np.ndarray | None:
        """The unweighted term per sample (S), or None when it does not apply this cycle."""
        raise NotImplementedError
