"""AmclConvergenceEvaluator (easynav_costmap_localizer/AmclConvergenceEvaluator): the AMCL
particle cloud has spread out (localization diverged).
"""

from __future__ import annotations

import math

from easynav.core.nav_state import NavState
from easynav.core.plugins import Param
from easynav.core.types import DiagnosticLevel
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.diagnostic.evaluator_base import EvaluatorBase


class AmclConvergenceEvaluator(EvaluatorBase):
    """hardware_id ``localizer.amcl``: ERROR while ``localizer.amcl.covariance_trace`` (var x +
    var y + var yaw, written by the AMCL localizers) exceeds ``covariance_threshold`` (1.0) or is
    not finite; OK otherwise, and OK "no covariance data yet" before AMCL writes it. Values:
    ``covariance_trace``.

    Thread contract: as :class:`EvaluatorBase`.
    """

    HARDWARE_ID = "localizer.amcl"

    READS = (keys.AMCL_COVARIANCE_TRACE,)
    PARAMETERS = (
        Param("covariance_threshold", 1.0, "a covariance trace above this is an ERROR", "", gt=0.0),
    )

    def on_initialize(self) -> None:
        self.covariance_threshold = self.params.covariance_threshold

    def update(self, nav_state: NavState) -> None:
        if not nav_state.has(keys.AMCL_COVARIANCE_TRACE):
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "no covariance data yet")
            return
        trace = float(nav_state.get(keys.AMCL_COVARIANCE_TRACE))
        values = {"covariance_trace": f"{trace:.4g}"}
        if not math.isfinite(trace) or trace > self.covariance_threshold:
            self.publish_diagnostic(
                nav_state,
                DiagnosticLevel.ERROR,
                f"particle filter diverged (covariance trace {trace:.3g} > "
                f"{self.covariance_threshold:g})",
                values,
            )
        else:
            self.publish_diagnostic(nav_state, DiagnosticLevel.OK, "converged", values)
