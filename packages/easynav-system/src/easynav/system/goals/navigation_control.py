"""NavigationControl: native form of easynav_interfaces/NavigationControl."""

from __future__ import annotations

from dataclasses import dataclass, field

from easynav.core.types import Goals, Header, PoseStamped
from easynav.system.goals.copies import copy_goals, copy_header, copy_pose_stamped
from easynav.system.goals.navigation_control_type import NavigationControlType


@dataclass(slots=True)
class NavigationControl:
    """One message of the goal protocol on ``easynav_control`` (both directions).

    ``type`` is a :class:`NavigationControlType` for every value the message defines; a value
    outside that set (from a faulty sender) is kept as a plain ``int`` so that the goal manager
    can answer it with ERROR "Unable to process message" instead of dropping it.
    Durations are float seconds. ``estimated_time_remaining`` is 0.0 while unknown (the robot
    has not moved far enough yet to measure its speed).

    Thread contract: a plain value; copy it (:meth:`copy`) before handing it to another thread
    that may modify it.
    """

    type: NavigationControlType | int = NavigationControlType.REQUEST
    header: Header = field(default_factory=Header)
    seq: int = 0
    user_id: str = ""
    nav_current_user_id: str = ""
    goals: Goals = field(default_factory=Goals)
    status_message: str = ""
    current_pose: PoseStamped = field(default_factory=PoseStamped)
    navigation_time: float = 0.0
    estimated_time_remaining: float = 0.0
    distance_covered: float = 0.0
    distance_to_goal: float = 0.0

    def copy(self) -> NavigationControl:
        """A deep copy (goals and poses included)."""
        return NavigationControl(
            type=self.type,
            header=copy_header(self.header),
            seq=self.seq,
            user_id=self.user_id,
            nav_current_user_id=self.nav_current_user_id,
            goals=copy_goals(self.goals),
            status_message=self.status_message,
            current_pose=copy_pose_stamped(self.current_pose),
            navigation_time=self.navigation_time,
            estimated_time_remaining=self.estimated_time_remaining,
            distance_covered=self.distance_covered,
            distance_to_goal=self.distance_to_goal,
        )

    @property
    def type_name(self) -> str:
        """``"ACCEPT"``, ``"FEEDBACK"``...; ``"UNKNOWN(<n>)"`` for an undefined type."""
        return NavigationControlType.name_of(int(self.type))
