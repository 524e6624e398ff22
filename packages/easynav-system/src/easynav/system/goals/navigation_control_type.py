"""NavigationControlType: the ``type`` constants of easynav_interfaces/NavigationControl."""

from __future__ import annotations

from enum import IntEnum


class NavigationControlType(IntEnum):
    """Message types of the goal protocol, with the values of NavigationControl.msg.

    Clients send REQUEST, CANCEL, PAUSE and RESUME; the goal manager answers with the others.
    """

    REQUEST = 0
    REJECT = 1
    ACCEPT = 2
    FEEDBACK = 3
    FINISHED = 4
    FAILED = 5
    CANCEL = 6
    CANCELLED = 7
    ERROR = 8
    PAUSE = 9
    RESUME = 10
    PAUSED = 11
    RESUMED = 12

    @classmethod
    def name_of(cls, value: int) -> str:
        """The constant's name, or ``UNKNOWN(<value>)`` for a value outside the message's set."""
        try:
            return cls(value).name
        except ValueError:
            return f"UNKNOWN({value})"
