"""StraightMotionValidator: OMPL motion checks of SE2 straight segments in one numpy call.

Imports OMPL: import this module only where OMPL is installed (the planner does, lazily).
"""

from __future__ import annotations

import math

import numpy as np
from ompl import base as ob

from easynav.planners.footprint_checker import FootprintChecker


class StraightMotionValidator(ob.MotionValidator):
    """Checks an SE2 motion (a straight segment in x, y; the yaw does not matter to a disc) by
    testing its points every ``step`` metres at once with :meth:`FootprintChecker.are_free`,
    instead of one Python call per state as OMPL's DiscreteMotionValidator does.

    Only the two-state ``checkMotion`` is meaningful (OMPL's Python trampoline does not fill
    the last valid state): use it with planners that do not ask for it (not the KPIECE family).

    Thread contract: called by OMPL in the planning thread. Exceptions: none (a non-finite state
    is invalid).
    """

    def __init__(self, si, checker: FootprintChecker, step: float) -> None:
        super().__init__(si)
        self.checker = checker
        self.step = float(step)
        #: Motions checked (for statistics).
        self.count = 0

    def checkMotion(self, s1, s2) -> bool:  # noqa: N802 - OMPL's name
        """Whether every point of the segment ``s1``-``s2`` (``s2`` included) is free."""
        self.count += 1
        x1, y1, x2, y2 = s1.getX(), s1.getY(), s2.getX(), s2.getY()
        length = math.hypot(x2 - x1, y2 - y1)
        n = max(1, math.ceil(length / self.step))
        if n <= 8:  # a few states: scalar tests are cheaper than building arrays
            is_free = self.checker.is_free
            return all(
                is_free(x1 + (x2 - x1) * k / n, y1 + (y2 - y1) * k / n) for k in range(1, n + 1)
            )
        checker = self.checker
        # The map is a rectangle: a segment whose ends are on it is on it, so the points need
        # no bounds test and truncation is the floor.
        if not (checker.is_on_map(x1, y1) and checker.is_on_map(x2, y2)):
            return False
        t = np.arange(1, n + 1, dtype=float) / n
        ix = ((x1 - checker.origin_x + (x2 - x1) * t) * checker.cells_per_m).astype(np.intp)
        iy = ((y1 - checker.origin_y + (y2 - y1) * t) * checker.cells_per_m).astype(np.intp)
        # A rounding of the last point could step one past the far edge: clip it back.
        np.minimum(ix, checker.free.shape[1] - 1, out=ix)
        np.minimum(iy, checker.free.shape[0] - 1, out=iy)
        return bool(checker.free[iy, ix].all())
