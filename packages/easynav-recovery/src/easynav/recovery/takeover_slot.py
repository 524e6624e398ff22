"""TakeoverSlot: a velocity decided in the non-RT loop and proposed by the RT loop every cycle."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from easynav.core.types import Twist


class TakeoverSlot:
    """The TAKEOVER velocity of a recovery behaviour while it drives the robot.

    A proposal lasts one RT cycle, so whoever drives the robot must propose on every RT cycle;
    deciding (distances, timeouts, perception) is non-RT work. The non-RT loop ``engage``\\ s the
    slot, ``command``\\ s velocities and ``release``\\ s it; the RT loop reads :meth:`current` every
    cycle and proposes it.

    Fail-safe: when the non-RT loop has not refreshed the command for ``max_age`` seconds (a
    plugin hangs the non-RT cycle; see :meth:`for_cycle`), :meth:`current` returns zero, so a
    stalled decision never keeps the robot moving. Measured with the monotonic clock
    (``clock``), not ROS time.

    Thread contract: ``engage``/``command``/``release`` from the non-RT thread, ``current`` from
    the RT thread; a lock held for a few assignments only.
    """

    DEFAULT_MAX_AGE = 0.5

    @classmethod
    def for_cycle(cls, system_freq: float) -> TakeoverSlot:
        """A slot whose commands stay fresh for 0.5 s or three non-RT periods, the longer."""
        return cls(max(cls.DEFAULT_MAX_AGE, 3.0 / system_freq))

    def __init__(
        self, max_age: float = DEFAULT_MAX_AGE, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.max_age = max_age
        self._clock = clock
        self._lock = threading.Lock()
        self._engaged = False
        self._twist = Twist()
        self._since = 0.0

    @property
    def engaged(self) -> bool:
        """True while a behaviour drives the robot."""
        return self._engaged

    def engage(self) -> None:
        """Start driving; the command is zero until the first :meth:`command`."""
        with self._lock:
            self._engaged = True
            self._twist = Twist()
            self._since = self._clock()

    def command(self, twist: Twist) -> None:
        """Set the velocity to propose (engages the slot if needed)."""
        with self._lock:
            self._engaged = True
            self._twist = Twist(twist.vx, twist.vy, twist.vz, twist.wx, twist.wy, twist.wz)
            self._since = self._clock()

    def release(self) -> None:
        """Stop driving: the controller gets the robot back."""
        with self._lock:
            self._engaged = False
            self._twist = Twist()

    def current(self) -> Twist | None:
        """The velocity to propose this RT cycle (a new object), zero if stale, None if released."""
        with self._lock:
            if not self._engaged:
                return None
            if self._clock() - self._since > self.max_age:
                return Twist()
            t = self._twist
            return Twist(t.vx, t.vy, t.vz, t.wx, t.wy, t.wz)
