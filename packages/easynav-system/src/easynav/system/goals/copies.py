"""Field-wise copies of the small native types the goal messages carry.

``copy.deepcopy`` costs ~10× more on these slotted dataclasses; the goal manager copies a
message or two per FEEDBACK, inside a 200 Hz loop.
"""

from __future__ import annotations

from easynav.core.types import Goals, Header, Pose, PoseStamped


def copy_header(header: Header) -> Header:
    """An independent copy of a Header."""
    return Header(header.stamp, header.frame_id)


def copy_pose_stamped(pose: PoseStamped) -> PoseStamped:
    """An independent copy of a PoseStamped."""
    q = pose.pose
    return PoseStamped(
        header=Header(pose.header.stamp, pose.header.frame_id),
        pose=Pose(q.x, q.y, q.z, q.qx, q.qy, q.qz, q.qw),
    )


def copy_goals(goals: Goals) -> Goals:
    """An independent copy of a Goals list."""
    return Goals(
        header=copy_header(goals.header), goals=[copy_pose_stamped(g) for g in goals.goals]
    )
