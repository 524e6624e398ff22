"""SimpleRecoveryManager (easynav_simple_recovery/SimpleRecoveryManager): a readable recovery
system with one simple case for each thing a recovery system can do.
"""

from __future__ import annotations

import math

import numpy as np

from easynav.common.sensors import PointPerception
from easynav.common.tf import get_tf_buffer
from easynav.core.nav_state import NavState
from easynav.core.plugins import Param, RecoveryManagerBase
from easynav.core.types import DiagnosticStatus, Odometry, Twist, TwistStamped
from easynav.recovery import nav_state_keys as keys
from easynav.recovery.activation_aware_schedule import ActivationAwareSchedule
from easynav.recovery.fused_point_cloud import FusedPointCloud
from easynav.recovery.navigation_context import (
    commanded_velocity,
    has_active_goal,
    navigation_paused,
    protective_stop,
)
from easynav.recovery.simple.simple_mitigation import SimpleMitigation
from easynav.recovery.takeover_slot import TakeoverSlot

#: The parameter that slowing down changes, as system_node lists it in reconfigured_parameters.
SLOW_DOWN_NODE = "controller_node"
SLOW_DOWN_PARAMETER = "robot_limits.max_linear_vel"
SLOW_DOWN_KEY = f"{SLOW_DOWN_NODE}/{SLOW_DOWN_PARAMETER}"

#: Below this controller speed (m/s) the robot is not "commanded" for the stuck check.
MIN_COMMANDED_SPEED = 0.01


class SimpleRecoveryManager(RecoveryManagerBase):
    """A small recovery system, written to be read from top to bottom.

    RT (:meth:`update_rt`, every RT cycle):

    - **brake** (zero OVERRIDE) when moving forward and a point with
      ``min_obstacle_z < z < robot_geometry.height`` lies in front of the robot, within
      ``robot_geometry.radius`` sideways and ``stop_distance`` beyond the radius ahead (points
      fused into the robot footprint frame);
    - otherwise **propose the mitigation** chosen by :meth:`update` (TAKEOVER): a proposal lasts
      one RT cycle, so it is proposed on every cycle while the mitigation lasts.

    Non-RT (:meth:`update`, every non-RT cycle), most severe case first:

    1. no new data from any point sensor for ``sensors_timeout`` (counted from activation until
       the first data arrives) → ``request_shutdown``;
    2. no mission → nothing to recover (a slow-down of the last mission is undone);
    3. position variance (x or y) above ``max_position_variance`` → hold the mission's progress
       and rotate at ``rotate_speed``; ``abort_mission`` after ``relocalize_timeout``;
    4. stuck (the controller commands motion but the robot moved less than ``stuck_distance`` in
       ``stuck_time``) → back up at ``backup_speed`` for ``backup_time``; after
       ``max_backup_attempts``, slow down through ``request_reconfigure``
       (``controller_node.robot_limits.max_linear_vel = slow_down_max_linear_vel``; 0: never);
       still stuck → ``abort_mission``.

    Parameters: :attr:`PARAMETERS`. The deprecated ``robot_radius`` and ``max_obstacle_z`` stand
    in for ``system_node.robot_geometry.radius``/``height`` (with a warning) where the params
    file does not set that robot_geometry field.

    Thread contract: ``update_rt`` in the RT thread, ``update`` in the non-RT thread; they share
    only a :class:`TakeoverSlot` (locked) and immutable parameters. Exceptions: ``initialize``
    raises ``PluginConfigurationError`` naming a bad parameter; the host contains the rest.
    """

    PARAMETERS = (
        Param("stop_distance", 0.3, "brake for points this far beyond the radius ahead", "m",
              ge=0.0),
        Param("min_obstacle_z", 0.05, "points at or below this height are ground", "m"),
        Param("robot_radius", math.nan, "deprecated: system_node robot_geometry.radius", "m",
              ge=0.0, allow_nan=True, dynamic=False),
        Param("max_obstacle_z", math.nan, "deprecated: system_node robot_geometry.height", "m",
              ge=0.0, allow_nan=True, dynamic=False),
        Param("sensors_timeout", 5.0, "no point data for this long: request_shutdown", "s",
              gt=0.0),
        Param("max_position_variance", 1.0, "x or y variance above this: relocalise", "m²",
              gt=0.0),
        Param("relocalize_timeout", 20.0, "abort the mission after relocalising this long", "s",
              gt=0.0),
        Param("rotate_speed", 0.5, "turn rate while relocalising", "rad/s"),
        Param("stuck_time", 10.0, "stuck: commanded but moved less than stuck_distance in this",
              "s", gt=0.0),
        Param("stuck_distance", 0.05, "stuck: moved less than this in stuck_time", "m", gt=0.0),
        Param("backup_speed", 0.1, "speed of a backup (driven backwards)", "m/s", ge=0.0),
        Param("backup_time", 2.0, "duration of a backup", "s", ge=0.0),
        Param("max_backup_attempts", 3, "backups before slowing down", ge=0),
        Param("slow_down_max_linear_vel", 0.1,
              "robot_limits.max_linear_vel after the backups (0: never slow down)", "m/s",
              ge=0.0),
    )
    READS = (
        keys.ROBOT_POSE, keys.CMD_VEL, keys.GOALS, keys.NAVIGATION_STATE, keys.NAVIGATION_PAUSED,
        keys.SAFETY_STATUS, keys.SENSORS_DIAGNOSTIC, keys.RECONFIGURED_PARAMETERS,
    )
    WRITES = (keys.PROPOSAL_OVERRIDE, keys.PROPOSAL_TAKEOVER)

    def on_initialize(self) -> None:
        self._read_tuning()
        self.robot_radius = self.geometry_or_deprecated("robot_radius", "radius")
        self.max_obstacle_z = self.geometry_or_deprecated("max_obstacle_z", "height")

        self.schedule = ActivationAwareSchedule(self.freq, self._on_activation)
        self._slot = TakeoverSlot.for_cycle(self.context.system_freq)
        self._cloud = FusedPointCloud(
            self.context.namespace,
            z_min=self.min_obstacle_z,
            z_max=self.max_obstacle_z,
            strict_z=True,
            logger=self.logger,
        )
        self._activated = True
        # Non-RT state.
        self.mitigation = SimpleMitigation.NONE
        self._mitigation_start = 0.0
        self.backup_attempts = 0
        self._stuck_reference: tuple[float, float] | None = None
        self._stuck_reference_time = 0.0
        self._newest_sensor_stamp = math.nan
        self._newest_sensor_arrival = 0.0
        self._shutdown_requested = False
        self._restore_requested = False
        self._abort_requested = False

    def _read_tuning(self) -> None:
        # Plain attributes for the readable algorithm below; refreshed on a runtime change.
        p = self.params
        self.stop_distance = p.stop_distance
        self.min_obstacle_z = p.min_obstacle_z
        self.sensors_timeout = p.sensors_timeout
        self.max_position_variance = p.max_position_variance
        self.relocalize_timeout = p.relocalize_timeout
        self.rotate_speed = p.rotate_speed
        self.stuck_time = p.stuck_time
        self.stuck_distance = p.stuck_distance
        self.backup_speed = p.backup_speed
        self.backup_time = p.backup_time
        self.max_backup_attempts = p.max_backup_attempts
        self.slow_down_max_linear_vel = p.slow_down_max_linear_vel

    def on_parameter_changed(self, name: str, value: object) -> None:
        """Tuning applies from the next cycle (``min_obstacle_z`` at the next configure)."""
        self._read_tuning()

    def _on_activation(self) -> None:
        self._activated = True

    def on_cleanup(self) -> None:
        self._slot.release()

    # ── RT cycle: react fast, and propose the chosen mitigation ───────────────────────────────
    def update_rt(self, nav_state: NavState) -> bool:
        """Brake before an obstacle ahead, else drive the mitigation. RT thread."""
        takeover = self._slot.current()
        # Our mitigations never move forward: the brake watches the controller's motion.
        if takeover is None and self._moving_forward(nav_state) and self._obstacle_ahead(nav_state):
            self.actions.override_velocity(Twist())
            return True
        if takeover is not None:
            self.actions.command_velocity(takeover)
            return True
        return False

    def _moving_forward(self, nav_state: NavState) -> bool:
        command = commanded_velocity(nav_state)
        return command is not None and command.vx > 0.0

    def _obstacle_ahead(self, nav_state: NavState) -> bool:
        tf_info = get_tf_buffer(self.context.namespace).get_tf_info()
        self._cloud.update(nav_state, tf_info.robot_footprint_frame)
        # Where the points are now, not where they were when the sensor fired.
        points = self._cloud.carried_to_latest(tf_info.odom_frame)
        if points.shape[0] == 0:
            return False
        r = self.robot_radius
        x, y = points[:, 0], points[:, 1]
        ahead = (x >= 0.0) & (x <= r + self.stop_distance) & (np.abs(y) <= r)
        return bool(np.any(ahead))

    # ── Non-RT cycle: diagnose and decide ────────────────────────────────────────────────────
    def update(self, nav_state: NavState) -> None:
        """Decide, most severe case first. Non-RT thread."""
        now = self.now()
        if now <= 0.0:
            # Simulated time before the first /clock message: nothing can be timed yet. The
            # watches start with the clock, or the first message (seconds into the
            # simulation) would look like sensors_timeout without data.
            return
        if self._activated:
            self._activated = False
            self._newest_sensor_arrival = now  # sensors get sensors_timeout again
            self._stuck_reference = None

        # Case 1: no sensor data. Driving blind is not safe: terminate EasyNav.
        if self._sensors_lost(nav_state, now):
            self._stop_mitigation()
            if not self._shutdown_requested:
                self._shutdown_requested = True
                self.actions.request_shutdown(
                    f"no new sensor data for sensors_timeout = {self.sensors_timeout:g} s"
                )
            return

        # No mission, nothing to recover. Undo the slow-down of the last one, if any.
        if not has_active_goal(nav_state):
            self._stop_mitigation()
            self.backup_attempts = 0
            self._abort_requested = False
            if self._slowed_down(nav_state):
                if not self._restore_requested:
                    self._restore_requested = self.actions.request_restore_parameters(
                        "mission ended: normal speed again"
                    )
            else:
                self._restore_requested = False
            return
        if self._abort_requested:
            return  # the abort is applied by the goal manager in its next cycle

        # Case 2: localization lost. The pose cannot be trusted: no goal may be taken as reached
        # (hold), and rotating in place helps the localizer find itself again.
        variance = self._position_variance(nav_state)
        if variance > self.max_position_variance:
            if self.mitigation is not SimpleMitigation.ROTATE:
                self._stop_mitigation()
                self._start(SimpleMitigation.ROTATE, now, "localization lost, rotating")
                self.actions.hold_mission_progress(True)
            elif now - self._mitigation_start > self.relocalize_timeout:
                self._stop_mitigation()
                self._abort(
                    f"could not relocalize in relocalize_timeout = {self.relocalize_timeout:g} s "
                    f"(position variance {variance:.3g} > {self.max_position_variance:g})"
                )
                return
            self._slot.command(Twist(wz=self.rotate_speed))
            return
        if self.mitigation is SimpleMitigation.ROTATE:
            self._stop_mitigation()  # relocalized

        # Case 3: the robot does not move although the controller commands it. Back up, then let
        # the controller try again; if that is not enough, try again slower; then give up.
        if self._robot_stuck(nav_state, now):
            self.backup_attempts += 1
            if self.backup_attempts <= self.max_backup_attempts:
                self._start(
                    SimpleMitigation.BACK_UP,
                    now,
                    f"stuck, backing up (attempt {self.backup_attempts} of "
                    f"{self.max_backup_attempts})",
                )
            elif self.slow_down_max_linear_vel > 0.0 and not self._slowed_down(nav_state):
                # Applied between cycles through a reconfiguration: this manager is reloaded too,
                # so its members start over (reconfigured_parameters tells the new one).
                accepted = self.actions.request_reconfigure(
                    [(SLOW_DOWN_NODE, SLOW_DOWN_PARAMETER, self.slow_down_max_linear_vel)],
                    "stuck: slowing down",
                )
                if not accepted:
                    self._abort(
                        f"stuck after {self.max_backup_attempts} backup attempts "
                        "(slowing down was refused)"
                    )
            else:
                slower = " at the reduced speed" if self._slowed_down(nav_state) else ""
                self._abort(f"stuck after {self.max_backup_attempts} backup attempts{slower}")
            return

        if self.mitigation is SimpleMitigation.BACK_UP:
            if now - self._mitigation_start > self.backup_time:
                self._stop_mitigation()
            else:
                self._slot.command(Twist(vx=-self.backup_speed))
        # Case 4: all fine, the controller drives.

    # ── Cases ────────────────────────────────────────────────────────────────────────────────
    def _sensors_lost(self, nav_state: NavState, now: float) -> bool:
        # New data changes the newest stamp of the valid perceptions (expired ones are invalid).
        perceptions = nav_state.get_by_type(PointPerception)
        if not perceptions and not self._sensors_without_data(nav_state):
            return False  # no point sensor configured
        newest = max((p.stamp for p in perceptions.values() if p.valid), default=math.nan)
        if now < self._newest_sensor_arrival:
            self._newest_sensor_arrival = now  # the clock went back (simulation restarted)
        if not math.isnan(newest) and newest != self._newest_sensor_stamp:
            self._newest_sensor_stamp = newest
            self._newest_sensor_arrival = now
        return now - self._newest_sensor_arrival > self.sensors_timeout

    @staticmethod
    def _sensors_without_data(nav_state: NavState) -> bool:
        # A sensor that never sent anything has no perception in NavState yet: sensors_node
        # lists it in its diagnostic, so the watch counts from activation until the first data.
        status = nav_state.get_or(keys.SENSORS_DIAGNOSTIC, None)
        return isinstance(status, DiagnosticStatus) and bool(status.values.get("no_data"))

    def _position_variance(self, nav_state: NavState) -> float:
        if not nav_state.has(keys.ROBOT_POSE):
            return 0.0
        covariance = nav_state.get(keys.ROBOT_POSE, Odometry).pose_covariance
        return float(max(covariance[0, 0], covariance[1, 1]))

    def _slowed_down(self, nav_state: NavState) -> bool:
        changed = nav_state.get_or(keys.RECONFIGURED_PARAMETERS, None)
        return bool(changed) and SLOW_DOWN_KEY in changed

    def _robot_stuck(self, nav_state: NavState, now: float) -> bool:
        # Only the controller's own motion counts: restart while a mitigation drives, while the
        # controller commands no motion, or while the robot may not move (pause, safety stop).
        commanded = (
            nav_state.has(keys.CMD_VEL)
            and abs(nav_state.get(keys.CMD_VEL, TwistStamped).twist.vx) > MIN_COMMANDED_SPEED
            and not navigation_paused(nav_state)
            and not protective_stop(nav_state)
        )
        if (
            self.mitigation is not SimpleMitigation.NONE
            or not commanded
            or not nav_state.has(keys.ROBOT_POSE)
        ):
            self._stuck_reference = None
            return False
        pose = nav_state.get(keys.ROBOT_POSE, Odometry).pose
        reference = self._stuck_reference
        if reference is None or math.hypot(pose.x - reference[0], pose.y - reference[1]) > (
            self.stuck_distance
        ):
            self._stuck_reference = (pose.x, pose.y)  # moving: restart
            self._stuck_reference_time = now
            return False
        if now - self._stuck_reference_time < self.stuck_time:
            return False
        self._stuck_reference = None
        return True

    # ── Mitigations ──────────────────────────────────────────────────────────────────────────
    def _start(self, mitigation: SimpleMitigation, now: float, why: str) -> None:
        self.logger.warning(f"Recovery: {why}")
        self.mitigation = mitigation
        self._mitigation_start = now
        self._slot.engage()
        if mitigation is SimpleMitigation.ROTATE:
            self._slot.command(Twist(wz=self.rotate_speed))
        else:
            self._slot.command(Twist(vx=-self.backup_speed))

    def _stop_mitigation(self) -> None:
        if self.mitigation is SimpleMitigation.ROTATE:
            self.actions.hold_mission_progress(False)
        self.mitigation = SimpleMitigation.NONE
        self._slot.release()

    def _abort(self, reason: str) -> None:
        self.logger.error(f"Recovery: aborting the mission: {reason}")
        self._abort_requested = True
        self.actions.abort_mission(reason)
