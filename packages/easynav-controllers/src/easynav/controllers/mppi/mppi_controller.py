"""The plugin easynav_mppi_controller/MPPIController."""

from __future__ import annotations

from typing import Any

from easynav.common.tf import get_tf_buffer
from easynav.controllers.controller_keys import GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW, MAP
from easynav.controllers.legacy_limits import capped_limits, warn_set_caps
from easynav.controllers.map_as_costmap import MapAsCostmap
from easynav.controllers.mppi.mppi_optimizer import (
    MPPI_LIMIT_CAPS,
    MPPI_PARAMETERS,
    NO_PATH,
    MppiCommand,
    MppiOptimizer,
)
from easynav.controllers.mppi.rollout import numba_available
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL, NAVIGATION_STATE, PATH, ROBOT_POSE
from easynav.core.plugins import ControllerMethodBase, PluginConfigurationError
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Twist, TwistStamped


class MPPIController(ControllerMethodBase):
    """MPPI (:class:`MppiOptimizer`) with critics as plugins, as an EasyNav controller plugin.

    Parameters: :data:`MPPI_PARAMETERS` under ``<alias>.``: the original's (``num_samples``
    100, ``horizon_steps`` 10, ``dt`` 0.1, ``lambda`` 0.1; its limits are deprecated caps on the
    limits in force; ``fov`` and ``safety_radius`` are accepted and, as in the original, have no
    effect), the sampling and critic list, and each critic's under ``<alias>.<Critic>.``. Every
    cycle reads the limits in force (``get_robot_limits()``), the goal tolerances and the
    parameters. ``num_samples``, ``horizon_steps`` and ``seed`` change only by reconfiguring.

    NavState: reads ``navigation_state`` ("IDLE": zero command), ``path``, ``robot_pose``,
    ``goal_tolerance.position`` / ``goal_tolerance.yaw`` (else ``xy_goal_tolerance`` /
    ``yaw_goal_tolerance``), ``map`` (Costmap2D for the CostCritic and PathAlignCritic, or a
    SimpleMap or GridMap read through :class:`MapAsCostmap`; absent: no obstacle terms); writes
    ``cmd_vel`` (a new stamp every cycle; zero without path or pose, at the goal and when idle).

    Thread contract: ``initialize`` in the configuring thread, ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter at configure time.
    """

    PARAMETERS = MPPI_PARAMETERS
    READS = (NAVIGATION_STATE, PATH, ROBOT_POSE, GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW, MAP)
    WRITES = (CMD_VEL,)

    def __init__(self) -> None:
        super().__init__()
        self.optimizer: MppiOptimizer | None = None
        self.state = NO_PATH
        self.last_command = MppiCommand()
        self._last_time: float | None = None
        self._path: Path | None = None
        self._map_as_costmap = MapAsCostmap()
        self._path_xy_yaw = None

    def on_initialize(self) -> None:
        warn_set_caps(MPPI_LIMIT_CAPS, self.params, self.plugin_name, self.logger.warning)
        if self.optimizer is not None:  # reconfiguration: stop the previous noise worker
            self.optimizer.close()
        try:
            self.optimizer = MppiOptimizer(self.params)
        except ValueError as exc:
            raise PluginConfigurationError(f"{self.plugin_name}.{exc}") from None
        if not numba_available():
            self.logger.info(
                f"{self.plugin_name}: numba not installed, rollouts use numpy "
                "(pip install easynav-controllers[numba] for the fast path)"
            )
        self.state = NO_PATH
        self._last_time = None
        self._path = None

    def on_cleanup(self) -> None:
        if self.optimizer is not None:
            self.optimizer.close()

    def on_parameter_changed(self, name: str, value: Any) -> None:
        if name == "critics" and self.optimizer is not None:
            self.optimizer.configure_critics()

    def limits(self) -> RobotLimits:
        """The limits in force, cut down by the deprecated per-controller limits that are set."""
        return capped_limits(self.get_robot_limits(), MPPI_LIMIT_CAPS, self.params)

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel``. RT thread."""
        now = self.now()
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        path = nav_state.get(PATH, Path) if nav_state.has(PATH) else None
        robot = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
        idle = nav_state.get_or(NAVIGATION_STATE, "ACTIVE") == "IDLE"
        optimizer = self.optimizer
        if (idle or optimizer is None or path is None or len(path) == 0 or robot is None
                or not robot.is_finite()):
            self._last_time = now
            if optimizer is not None:
                optimizer.reset()
            self.state = NO_PATH
            self.last_command = MppiCommand()
            nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist()))
            return
        elapsed = 1.0 / self.rt_freq if self._last_time is None else now - self._last_time
        if elapsed == 0.0 and self._last_time is not None:
            return  # triggered again within one clock tick: the previous command stands
        if elapsed < 0.0 or elapsed > 1.0:  # clock jump or a pause: no warm start to trust
            optimizer.reset()
            elapsed = 1.0 / self.rt_freq
        self._last_time = now
        if path is not self._path:  # the planner stores a new Path for each plan
            self._path, self._path_xy_yaw = path, path.as_xy_yaw()
        costmap = self._map_as_costmap(nav_state.get_or(MAP, None))
        command = optimizer.compute(
            (robot.pose.x, robot.pose.y, robot.pose.yaw),
            self._path_xy_yaw,
            elapsed,
            self.limits(),
            float(nav_state.get_or(GOAL_TOLERANCE_POSITION, self.params.xy_goal_tolerance)),
            float(nav_state.get_or(GOAL_TOLERANCE_YAW, self.params.yaw_goal_tolerance)),
            costmap,
            path_key=path,
            robot_radius=self.get_robot_geometry().radius,
        )
        self.state = command.state
        self.last_command = command
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist(vx=command.v, wz=command.w)))
