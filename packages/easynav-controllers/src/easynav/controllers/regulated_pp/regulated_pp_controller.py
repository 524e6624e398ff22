"""The plugin easynav_regulated_pp_controller/RegulatedPurePursuitController."""

from __future__ import annotations

import math

from easynav.common.tf import get_tf_buffer
from easynav.controllers.controller_keys import GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW, MAP
from easynav.controllers.legacy_limits import capped_limits, warn_set_caps
from easynav.controllers.map_as_costmap import MapAsCostmap
from easynav.controllers.regulated_pp.regulated_pure_pursuit import (
    NO_PATH,
    ROTATING_TO_GOAL,
    ROTATING_TO_HEADING,
    RPP_LIMIT_CAPS,
    RPP_PARAMETERS,
    RegulatedPurePursuit,
    RppCommand,
)
from easynav.core.nav_state import NavState
from easynav.core.nav_state_keys import CMD_VEL, NAVIGATION_STATE, PATH, ROBOT_POSE
from easynav.core.plugins import ControllerMethodBase, Topic
from easynav.core.robot import RobotLimits
from easynav.core.types import Header, Odometry, Path, Twist, TwistStamped

#: Seconds assumed since the previous cycle on the first one or after a pause (the original's).
DEFAULT_DT = 0.05


class RegulatedPurePursuitController(ControllerMethodBase):
    """Regulated Pure Pursuit (:class:`RegulatedPurePursuit`) as an EasyNav controller plugin.

    Parameters: :data:`RPP_PARAMETERS` under ``<alias>.`` (the original's names and defaults;
    its limit parameters are deprecated caps on the limits in force). Every cycle reads the
    limits in force (``get_robot_limits()``: ``controller_node.robot_limits`` cut by a slow-down
    mitigation or a speed zone), the goal tolerances and the parameters, so runtime changes take
    effect at once.

    NavState: reads ``navigation_state`` ("IDLE": zero command), ``path``, ``robot_pose``,
    ``goal_tolerance.position`` / ``goal_tolerance.yaw`` (else ``xy_goal_tolerance`` /
    ``yaw_goal_tolerance``), ``map`` (Costmap2D, or a SimpleMap or GridMap read through
    :class:`MapAsCostmap`, for obstacle regulation; absent: no obstacle regulation); writes
    ``cmd_vel`` (a new stamp every cycle, zero without path or pose, at the goal and when
    idle). Topics (relative, published only when subscribed): ``lookahead_point``,
    ``curvature_lookahead_point`` (PointStamped, z = 0.05), ``is_rotating_to_heading`` (Bool).

    Thread contract: ``initialize`` in the configuring thread, ``update_rt`` in the RT thread.
    Exceptions: :class:`PluginConfigurationError` naming the parameter at configure time.
    """

    PARAMETERS = RPP_PARAMETERS
    TOPICS = (
        Topic("lookahead_point", "geometry_msgs/msg/PointStamped", "pub",
              description="the carrot (published only when subscribed)"),
        Topic("curvature_lookahead_point", "geometry_msgs/msg/PointStamped", "pub",
              description="the curvature carrot (published only when subscribed)"),
        Topic("is_rotating_to_heading", "std_msgs/msg/Bool", "pub",
              description="rotating in place (published only when subscribed)"),
    )
    READS = (NAVIGATION_STATE, PATH, ROBOT_POSE, GOAL_TOLERANCE_POSITION, GOAL_TOLERANCE_YAW, MAP)
    WRITES = (CMD_VEL,)

    def __init__(self) -> None:
        super().__init__()
        self.algorithm = RegulatedPurePursuit()
        self.state = NO_PATH
        self.last_command = RppCommand()
        self._last_time: float | None = None
        self._map_as_costmap = MapAsCostmap()
        self._publishers: dict[str, object] = {}
        self._path: Path | None = None
        self._path_xy_yaw = None

    def on_initialize(self) -> None:
        warn_set_caps(RPP_LIMIT_CAPS, self.params, self.plugin_name, self.logger.warning)
        self.algorithm.reset()
        self.state = NO_PATH
        self._last_time = None
        self._path = None
        self._destroy_publishers()
        node = self.context.node
        if node is not None:
            from geometry_msgs.msg import PointStamped
            from std_msgs.msg import Bool

            for topic in ("lookahead_point", "curvature_lookahead_point"):
                self._publishers[topic] = node.create_publisher(PointStamped, topic, 10)
            self._publishers["is_rotating_to_heading"] = node.create_publisher(
                Bool, "is_rotating_to_heading", 10
            )

    def on_cleanup(self) -> None:
        self._destroy_publishers()

    def _destroy_publishers(self) -> None:
        node = self.context.node
        for publisher in self._publishers.values():
            if node is not None:
                node.destroy_publisher(publisher)
        self._publishers = {}

    def limits(self) -> RobotLimits:
        """The limits in force, cut down by the deprecated per-controller limits that are set."""
        return capped_limits(self.get_robot_limits(), RPP_LIMIT_CAPS, self.params)

    def update_rt(self, nav_state: NavState) -> None:
        """Compute and write ``cmd_vel``. RT thread."""
        now = self.now()
        frame = get_tf_buffer(self.context.namespace).get_tf_info().robot_footprint_frame
        path = nav_state.get(PATH, Path) if nav_state.has(PATH) else None
        robot = nav_state.get(ROBOT_POSE, Odometry) if nav_state.has(ROBOT_POSE) else None
        idle = nav_state.get_or(NAVIGATION_STATE, "ACTIVE") == "IDLE"
        if idle or path is None or len(path) == 0 or robot is None or not robot.is_finite():
            self._last_time = now
            self.algorithm.reset()
            self.state = NO_PATH
            self.last_command = RppCommand()
            nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist()))
            self._publish_debug(frame, now)
            return
        dt = DEFAULT_DT if self._last_time is None else now - self._last_time
        if dt == 0.0 and self._last_time is not None:
            return  # triggered again within one clock tick: the previous command stands
        if dt <= 0.0 or dt > 1.0:
            dt = DEFAULT_DT
        self._last_time = now
        costmap = self._map_as_costmap(nav_state.get_or(MAP, None))
        command = self.algorithm.compute(
            (robot.pose.x, robot.pose.y, robot.pose.yaw),
            self._xy_yaw(path),
            dt,
            self.limits(),
            self.params,
            float(nav_state.get_or(GOAL_TOLERANCE_POSITION, self.params.xy_goal_tolerance)),
            float(nav_state.get_or(GOAL_TOLERANCE_YAW, self.params.yaw_goal_tolerance)),
            costmap,
            self.get_robot_geometry().radius,
            path_key=path,
        )
        self.state = command.state
        self.last_command = command
        nav_state.set(CMD_VEL, TwistStamped(Header(now, frame), Twist(vx=command.v, wz=command.w)))
        self._publish_debug(path.header.frame_id, now)

    def _xy_yaw(self, path: Path):
        # The planner stores a new Path object for each plan: convert each one once.
        if path is not self._path:
            self._path, self._path_xy_yaw = path, path.as_xy_yaw()
        return self._path_xy_yaw

    def _publish_debug(self, frame: str, now: float) -> None:
        if not self._publishers:
            return
        command = self.last_command
        rotating = self.state in (ROTATING_TO_HEADING, ROTATING_TO_GOAL)
        publisher = self._publishers["is_rotating_to_heading"]
        if publisher.get_subscription_count() > 0:
            from std_msgs.msg import Bool

            publisher.publish(Bool(data=rotating))
        for topic, point in (
            ("lookahead_point", command.carrot),
            ("curvature_lookahead_point", command.curvature_carrot),
        ):
            publisher = self._publishers[topic]
            if point is None or publisher.get_subscription_count() == 0:
                continue
            from geometry_msgs.msg import PointStamped

            msg = PointStamped()
            msg.header.frame_id = frame
            sec = math.floor(now)
            msg.header.stamp.sec, msg.header.stamp.nanosec = int(sec), int((now - sec) * 1e9)
            msg.point.x, msg.point.y, msg.point.z = float(point[0]), float(point[1]), 0.05
            publisher.publish(msg)
