"""Collision: one contact between the robot and the world or an obstacle."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Collision:
    """The robot touched something at simulated time ``stamp`` at ``(x, y)``.

    ``with_what`` is ``"wall"`` or the moving obstacle's name.
    """

    stamp: float
    x: float
    y: float
    with_what: str

    def as_dict(self) -> dict:
        """A JSON-ready mapping."""
        return {"stamp": self.stamp, "x": self.x, "y": self.y, "with": self.with_what}
