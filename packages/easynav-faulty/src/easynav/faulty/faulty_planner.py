"""FaultyPlanner (easynav_planner/FaultyPlanner): a straight path to the goal that goes wrong."""

from __future__ import annotations

import math

import numpy as np

from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import GOALS, PATH, ROBOT_POSE
from easynav.core.plugins import PlannerMethodBase
from easynav.core.types import Goals, Header, Odometry, Path, Pose
from easynav.faulty.fault_injector import FaultInjector

#: Spacing of the poses of the straight path (m): about what grid planners produce.
PATH_STEP = 0.1


def straight_path(start: Pose, goal: Pose, header: Header, step: float = PATH_STEP) -> Path:
    """Poses every ``step`` m (or less) on the segment from ``start`` to ``goal``.

    Every pose faces along the segment; the last one is the goal itself (its orientation
    included). A start on the goal gives a one-pose path (the goal).
    """
    dx, dy = goal.x - start.x, goal.y - start.y
    distance = math.hypot(dx, dy)
    if distance == 0.0:
        return Path(header, [Pose(goal.x, goal.y, goal.z, goal.qx, goal.qy, goal.qz, goal.qw)])
    n = max(1, math.ceil(distance / step))
    t = np.linspace(0.0, 1.0, n + 1)
    xy_yaw = np.column_stack(
        (start.x + t * dx, start.y + t * dy, np.full(n + 1, math.atan2(dy, dx)))
    )
    path = Path.from_xy_yaw(xy_yaw[:-1], header)
    path.poses.append(Pose(goal.x, goal.y, goal.z, goal.qx, goal.qy, goal.qz, goal.qw))
    return path


class FaultyPlanner(PlannerMethodBase):
    """Works as a planner that goes straight to the goal, then injects a fault.

    Normal ``update``: writes NavState ``path`` = :func:`straight_path` from ``robot_pose`` to the
    first of ``goals`` (obstacles and maps ignored), stamped with the node clock, in the map
    frame; an empty path (no plan) while there is no goal or no finite ``robot_pose``.

    Faults (``<alias>.fault``, counted in ``update`` calls, see :class:`FaultInjector`):

    ============== ===============================================================================
    ``throw``      ``update`` raises :class:`InjectedFaultError`
    ``hang``       ``update`` blocks ``hang_time`` s, then works normally (the non-RT cycle
                   stalls; the RT cycle must not)
    ``empty_path`` writes an empty path (no plan), stamped now, whatever the goal
    ``freeze``     writes the last normal path again: same stamp, same (maybe old) goal
    ``nan``        writes the normal path with the middle pose's ``x`` and ``y`` NaN (a single
                   NaN pose when there is no plan)
    ============== ===============================================================================

    Parameters: :attr:`PARAMETERS`.

    Thread contract: ``initialize`` in the configuring thread; ``update`` in the non-RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter; ``update`` raises
    :class:`InjectedFaultError` with the ``throw`` fault.
    """

    FAULTS = ("throw", "hang", "empty_path", "freeze", "nan")
    PARAMETERS = FaultInjector.parameters(FAULTS)
    READS = (GOALS, ROBOT_POSE)
    WRITES = (PATH,)

    def __init__(self) -> None:
        super().__init__()
        self.injector = FaultInjector(self, self.FAULTS)
        self.last_path: Path | None = None

    def on_initialize(self) -> None:
        self.injector.read_parameters()
        self.last_path = None

    def update(self, nav_state: NavState) -> None:
        fault = self.injector.update()
        if fault == "throw":
            self.injector.throw("update")
        if fault == "hang":
            self.injector.hang()
        map_frame = get_tf_buffer(self.context.namespace).get_tf_info().map_frame
        header = Header(self.now(), map_frame)
        if fault == "empty_path":
            nav_state.set(PATH, Path(header, []))
            return
        if fault == "freeze":
            if self.last_path is None:
                self.last_path = Path(header, [])  # frozen from the first update
            nav_state.set(PATH, self.last_path)
            return
        path = self._plan(nav_state, header)
        if fault == "nan":
            if path.poses:
                middle = path.poses[len(path.poses) // 2]
                middle.x = middle.y = math.nan
            else:
                path.poses.append(Pose(math.nan, math.nan))
        else:
            self.last_path = path
        nav_state.set(PATH, path)

    def _plan(self, nav_state: NavState, header: Header) -> Path:
        goals = nav_state.get_or(GOALS, None)
        if not isinstance(goals, Goals) or len(goals) == 0:
            return Path(header, [])
        if not nav_state.has(ROBOT_POSE):
            return Path(header, [])
        robot = nav_state.get_safe(ROBOT_POSE, Odometry)  # written by the RT loop
        if not robot.pose.is_finite():
            return Path(header, [])
        return straight_path(robot.pose, goals.goals[0].pose, header)
