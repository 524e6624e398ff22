"""PerceptionEchoController (easynav_playground/PerceptionEchoController): a measuring instrument.

It answers every new point perception with a command that identifies it, so an outside process
can tell which ``cmd_vel`` a given scan caused (perception-to-action latency). Not a controller
for driving a robot.
"""

from __future__ import annotations

from easynav.common.sensors import PointPerception
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL
from easynav.core.plugins import ControllerMethodBase, Param
from easynav.core.types import Header, Twist, TwistStamped


class PerceptionEchoController(ControllerMethodBase):
    """Writes ``cmd_vel`` with ``vx = scale · (number of points of the newest perception)``.

    The benchmark varies the number of valid ranges in each scan it sends, so each scan maps to a
    distinct command value. Parameters: :attr:`PARAMETERS`.

    Thread contract: RT thread (``update_rt``).
    """

    PARAMETERS = (Param("scale", 1e-4, "command per point of the newest perception", "m/s"),)
    WRITES = (CMD_VEL,)

    def on_initialize(self) -> None:
        self._last_stamp = None

    def update_rt(self, nav_state: NavState) -> None:
        perceptions = nav_state.get_no_group(PointPerception)
        newest = max(perceptions.values(), key=lambda p: p.stamp, default=None)
        if newest is None or newest.stamp == self._last_stamp:
            return
        self._last_stamp = newest.stamp
        twist = Twist(vx=self.params.scale * len(newest.points))
        nav_state.set(CMD_VEL, TwistStamped(Header(self.now(), ""), twist))
