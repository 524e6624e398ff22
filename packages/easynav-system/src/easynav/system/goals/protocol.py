"""Names and texts of the goal-manager protocol: the topics, ids and reply texts of the
original EasyNav's goal manager (goals and feedback travel on topics, no services or actions).

These strings are part of the contract with the original EasyNav and its clients: tools match
on them, so they are kept byte for byte (including the table's capitalisation).
"""

from __future__ import annotations

from easynav.core import nav_state_keys as keys
from easynav.core.nav_state_keys import (
    GOAL_TOLERANCE_HEIGHT,
    GOAL_TOLERANCE_POSITION,
    GOAL_TOLERANCE_YAW,
)

# -- participants -------------------------------------------------------------------------------
SYSTEM_USER_ID = "easynav_system"
"""The goal manager's own id: it ignores messages carrying it."""

INITPOSE_USER_ID = "easynav_system_initpose"
"""The user id of requests made from ``goal_pose`` (e.g. RViz's "2D Goal Pose")."""

CLIENT_ID_SUFFIX = "_goal_manager_client"
"""A GoalManagerClient's id is ``<node name>`` + this suffix."""

# -- topics (relative: the node's namespace applies) ----------------------------------------------
CONTROL_TOPIC = "easynav_control"
GOAL_POSE_TOPIC = "goal_pose"
MANAGER_INFO_TOPIC = "easynav_manager_info"
QUEUE_DEPTH = 100

# -- status messages of the protocol table -------------------------------------------------------
GOALS_EMPTY = "Goals are empty"
GOAL_ACCEPTED = "Goal accepted"
PREEMPTED_BY_OTHERS = "Navigation preempted by others"
UNABLE_TO_PREEMPT = "Goal rejected; unable to preempt current active goal"
CANCEL_NOT_YOURS = "Trying to cancel a navigation not commanded by you"
NOTHING_TO_CANCEL = "Nothing to cancel; easynav is idle"
GOAL_CANCELLED = "Goal cancelled"
NOTHING_TO_PAUSE = "Nothing to pause; easynav is idle"
NOTHING_TO_RESUME = "Nothing to resume; easynav is idle"
NAVIGATION_PAUSED = "Navigation paused"
NAVIGATION_RESUMED = "Navigation resumed"
UNABLE_TO_PROCESS = "Unable to process message"
NAVIGATION_FINISHED = "Navigation successfully finished"
MISSION_ABORTED = "Mission aborted"
"""ERROR text of ``abort_mission`` when it is given an empty reason."""

# -- NavState keys and values ---------------------------------------------------------------------
# The core keys (easynav.core.nav_state_keys); ``keys.NAVIGATION_PAUSED`` is the key, this
# module's NAVIGATION_PAUSED the reply text.
KEY_GOALS = keys.GOALS
KEY_NAVIGATION_STATE = keys.NAVIGATION_STATE
KEY_NAVIGATION_PAUSED = keys.NAVIGATION_PAUSED
KEY_ROBOT_POSE = keys.ROBOT_POSE
KEY_PATH = keys.PATH
KEY_POSITION_TOLERANCE = GOAL_TOLERANCE_POSITION
KEY_HEIGHT_TOLERANCE = GOAL_TOLERANCE_HEIGHT
KEY_YAW_TOLERANCE = GOAL_TOLERANCE_YAW

NAVIGATION_IDLE = "IDLE"
"""Value of NavState ``navigation_state`` (a ``str``) when there is no mission."""

NAVIGATION_ACTIVE = "ACTIVE"
"""Value of NavState ``navigation_state`` (a ``str``) while a mission is under way."""
