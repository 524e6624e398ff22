"""MppiOptimizer: Model Predictive Path Integral control over a batch scored by critics.

Plain numpy (numba for the rollout loop when installed), without ROS: the plugin
(``mppi_controller``) feeds it the pose, the path, the costmap and the limits every RT cycle.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from easynav.controllers.goal_arrival import CREEP, TURN, GoalArrival, creep_command
from easynav.controllers.mppi.collision_model import CollisionModel
from easynav.controllers.mppi.critic import Critic
from easynav.controllers.mppi.critics import CRITICS, DEFAULT_CRITICS
from easynav.controllers.mppi.mppi_batch import MppiBatch
from easynav.controllers.mppi.noise_generator import NoiseGenerator
from easynav.controllers.mppi.rollout import constrain_and_integrate
from easynav.controllers.mppi.savitzky_golay import smooth_sequence
from easynav.controllers.regulated_pp.path_geometry import project_on_path
from easynav.controllers.regulated_pp.regulation import latched_angle, rotation_speed
from easynav.core.plugins import Param
from easynav.core.robot import RobotLimits
from easynav.core.types import Costmap2D, normalize_angle

NAN = math.nan

#: The original's parameters (easynav_mppi_controller: names, defaults, meaning), then the
#: additions (sampling noise, Nav2's control-cost term, iterations, smoothing, critics).
MPPI_OWN_PARAMETERS = (
    Param("num_samples", 100, "sampled control sequences per cycle (Nav2: batch_size)", ge=1,
          dynamic=False),
    Param("horizon_steps", 10, "steps of each sequence (Nav2: time_steps)", ge=2,
          dynamic=False),
    Param("dt", 0.1, "rollout step (Nav2: model_dt)", "s", gt=0.0),
    Param("lambda", 0.1, "softmin temperature (Nav2: temperature)", gt=0.0),
    Param("max_linear_velocity", NAN, "deprecated cap (original default 1.0)", "m/s", ge=0.0,
          allow_nan=True),
    Param("max_angular_velocity", NAN, "deprecated cap (original default 1.0)", "rad/s",
          ge=0.0, allow_nan=True),
    Param("max_linear_acceleration", NAN,
          "deprecated cap (original default 0.5) of the linear acceleration and deceleration",
          "m/s²", gt=0.0, allow_nan=True),
    Param("max_angular_acceleration", NAN,
          "deprecated cap (original default 1.0) of the angular acceleration and deceleration",
          "rad/s²", gt=0.0, allow_nan=True),
    Param("fov", math.pi / 2, "accepted, no effect (as in the original)", "rad", ge=0.0),
    Param("safety_radius", 0.6, "accepted, no effect (as in the original)", "m", ge=0.0),
    Param("vx_std", 0.2, "standard deviation of the sampled linear speed noise", "m/s", gt=0.0),
    Param("wz_std", 0.4, "standard deviation of the sampled angular speed noise", "rad/s",
          gt=0.0),
    Param("constant_noise_ratio", 0.5,
          "share of the noise variance held constant along each sample (arcs; 0: Nav2's "
          "white noise per step)", ge=0.0, le=1.0),
    Param("gamma", 0.015, "weight of the control cost γ·u·Σ⁻¹·ε (Nav2's)", ge=0.0),
    Param("iteration_count", 1, "optimisation iterations per cycle", ge=1),
    Param("use_smoothing", True, "Savitzky-Golay smoothing of the optimal sequence"),
    Param("seed", -1, "random seed of the sampling noise (-1: from the OS)", ge=-1,
          dynamic=False),
    Param("critics", list(DEFAULT_CRITICS), "the critics that score the batch, in order",
          type="str[]", choices=tuple(CRITICS)),
    Param("use_rotate_to_heading", True,
          "rotate in place first when the path ahead is far off the heading (Nav2's rotation "
          "shim): sampled turns left and right cancel out when the path is behind"),
    Param("rotate_to_heading_min_angle", 1.57,
          "angle to the path ahead that starts a rotation in place (stops below half of it; "
          "smaller ones are left to the critics, which steer round obstacles)",
          "rad", gt=0.0),
    Param("rotate_to_heading_lookahead_dist", 0.5, "distance along the path of that point", "m",
          gt=0.0),
    Param("xy_goal_tolerance", 0.25, "used only when NavState has no goal_tolerance.position",
          "m", gt=0.0),
    Param("yaw_goal_tolerance", 0.25, "used only when NavState has no goal_tolerance.yaw", "rad",
          gt=0.0),
)

#: Every parameter: the controller's own, then each critic's under ``<critic>.``.
MPPI_PARAMETERS = MPPI_OWN_PARAMETERS + tuple(
    p for critic in CRITICS.values() for p in critic.declarations()
)

#: Deprecated limit parameters: (parameter, RobotLimits field, kind).
MPPI_LIMIT_CAPS = (
    ("max_linear_velocity", "max_linear_vel", "max"),
    ("max_linear_velocity", "min_linear_vel", "min_neg"),
    ("max_angular_velocity", "max_angular_vel", "max"),
    ("max_linear_acceleration", "max_linear_acc", "max"),
    ("max_linear_acceleration", "max_linear_decel", "max"),
    ("max_angular_acceleration", "max_angular_acc", "max"),
    ("max_angular_acceleration", "max_angular_decel", "max"),
)

#: States reported with each command.
NO_PATH = "no_path"
FOLLOWING = "following"
#: The weighted mean collided: the best sample was applied instead.
FALLBACK = "fallback"
#: Every candidate collided: braking.
BLOCKED = "blocked"
ROTATING_TO_GOAL = "rotating_to_goal"
#: Turned at the goal but beyond its position tolerance: straight along the heading.
CREEPING_TO_GOAL = "creeping_to_goal"
ROTATING_TO_HEADING = "rotating_to_heading"
#: Stuck facing an obstacle: braking, then turning in place to the free heading nearest the
#: path ahead (see :data:`STUCK_SPEED_RATIO`).
TURNING_TO_FREE_HEADING = "turning_to_free_heading"
ARRIVED = "arrived"

#: Stuck: for :data:`STUCK_TIME` the applied sequence's mean speed over the horizon stayed
#: below this share of ``max_linear_vel`` while driving :data:`FREE_HEADING_DISTANCE` straight
#: ahead would collide. A robot that cut a bend's corner into the collision margin of the
#: obstacle inside it, facing the obstacle, finds every sample that drives ahead colliding and
#: every one that turns first costing the same as standing (the path critics measure where the
#: rollouts end): the softmin mean stands, and on the TurtleBot3 sandbox, at a pillar beside a
#: passage, it stood there for good (crept, with AMCL's noise, into the pillar).
STUCK_SPEED_RATIO = 0.1
#: How long (s) the robot must be stuck before it turns: a planned stop (a person stepping in
#: ahead) is slow for a moment, a stuck robot for good.
STUCK_TIME = 1.0
#: Headings tried for a free one (every 5 degrees), and how far straight ahead each must be
#: clear (m) to count as free.
FREE_HEADINGS = 72
FREE_HEADING_DISTANCE = 0.3
#: Heading error (rad) at which the turn to a free heading hands back to the optimisation.
FREE_HEADING_TOLERANCE = 0.05

#: Arc length (m) of the path kept ahead of the rollouts' reach.
PATH_MARGIN = 1.0
#: Applied commands kept for the smoothing of the next sequence.
HISTORY = 4
#: Seconds the collision guard of the command looks ahead beyond the robot's braking time
#: from full speed (``max_linear_vel / max_linear_decel``): a few cycles to react in.
GUARD_REACTION = 0.5


#: Spacing (m) the path is resampled to: the critics count path points (``offset_from_furthest``)
#: as Nav2 does on a costmap-resolution path, while a smoothed plan may have few, far vertices.
PATH_SPACING = 0.05


def densify_path(path_xy_yaw: np.ndarray, spacing: float = PATH_SPACING) -> np.ndarray:
    """The path with points added so no two consecutive ones are more than ``spacing`` apart.

    Every vertex is kept; points added on a segment take its start vertex's yaw.
    """
    path = np.asarray(path_xy_yaw, dtype=float)
    if len(path) < 2:
        return path.copy()
    lengths = np.hypot(*np.diff(path[:, :2], axis=0).T)
    pieces = np.maximum(np.ceil(lengths / spacing).astype(np.int64), 1)
    segment = np.repeat(np.arange(len(lengths)), pieces)
    fraction = (np.arange(pieces.sum()) - np.repeat(np.cumsum(pieces) - pieces, pieces)) / (
        np.repeat(pieces, pieces)
    )
    start, end = path[segment], path[segment + 1]
    out = np.empty((len(segment) + 1, 3))
    out[:-1, :2] = start[:, :2] + fraction[:, None] * (end[:, :2] - start[:, :2])
    out[:-1, 2] = start[:, 2]
    out[-1] = path[-1]
    return out


@dataclass(slots=True)
class MppiCommand:
    """One cycle's output: the command, the state and the optimal rollout (T×3, for debugging)."""

    v: float = 0.0
    w: float = 0.0
    state: str = NO_PATH
    optimal_path: np.ndarray | None = None


class MppiOptimizer:
    """MPPI over a batch of ``num_samples`` × ``horizon_steps`` sampled control sequences.

    Each cycle: the previous optimal sequence, shifted by the time elapsed (warm start), plus
    Gaussian noise (``vx_std``, ``wz_std``) gives the batch; the controls are held within the
    limits in force (speeds, and accelerations from the current command), the rollouts are
    integrated as a unicycle, the critics add their costs (plus Nav2's control cost ``gamma``),
    and the new sequence is the softmin-weighted mean (temperature ``lambda``), Savitzky–Golay
    smoothed with the last applied commands and constrained again. Its first command is applied,
    unless its rollout collides (:class:`CollisionModel`: an inscribed or lethal cell, or an
    obstacle within ``robot_radius`` + ``CostCritic.collision_margin``, or as near as the path
    goes) within the braking time from full speed plus :data:`GUARD_REACTION`: then the best
    sample's (state ``fallback``), and when that collides too the robot brakes, and once
    stopped turns on the spot towards the path ahead (state ``blocked``). Stuck facing an
    obstacle (for :data:`STUCK_TIME` slow, :data:`STUCK_SPEED_RATIO`, while driving
    :data:`FREE_HEADING_DISTANCE` straight ahead would collide; not near the goal), the robot
    brakes and turns on the spot to the free heading nearest the path ahead (state
    ``turning_to_free_heading``); a new goal, the goal's approach or the rotation to the path's
    heading cancel that turn.
    Inside the goal's xy tolerance it rotates in place to the goal yaw and stops within the yaw
    tolerance.

    Thread contract: owned by the plugin, RT thread only; not locked.
    Exceptions: :class:`ValueError` for an unknown critic name.
    """

    def __init__(self, params: Mapping[str, Any]) -> None:
        self.params = params
        self.critics: list[Critic] = []
        self.noise: NoiseGenerator | None = None
        self.configure_critics()
        self.reset()

    def configure_critics(self) -> None:
        """Instantiate the critics named in ``critics`` (call again after a change)."""
        critics = []
        for name in self.params["critics"]:
            if name not in CRITICS:
                raise ValueError(f"critics: unknown critic {name!r} (known: {sorted(CRITICS)})")
            critics.append(CRITICS[name](self.params))
        self.critics = critics

    def close(self) -> None:
        """Stop the noise worker thread (cleanup)."""
        if self.noise is not None:
            self.noise.close()
            self.noise = None

    def reset(self) -> None:
        """Forget the warm start, the command history, the path progress and the goal latch."""
        steps = self.params["horizon_steps"]
        if self.noise is None or self.noise.shape != (2, self.params["num_samples"], steps):
            self.close()
            seed = self.params["seed"]
            self.noise = NoiseGenerator(self.params["num_samples"], steps,
                                        None if seed < 0 else seed)
        self.sequence = np.zeros((steps, 2), dtype=np.float32)
        self.history = np.zeros((0, 2), dtype=np.float32)
        self.last = (0.0, 0.0)
        self._path_key: Any = None
        self._path = np.zeros((0, 3))
        self._s = np.zeros(0)
        self._segment = 0
        self.arrival = GoalArrival()
        self._rotating = False
        self._rotation_sign = 0.0
        self._blocked_sign = 0.0  # the latch of the turn in place when blocked
        self._forget_free_heading()
        self._held: float | None = None  # the CollisionModel's hold inside the margin
        self.last_batch: MppiBatch | None = None

    # -- path ----------------------------------------------------------------------------------
    def _local_path(self, position: np.ndarray, reach: float):
        path = self._path
        last = len(path) - 1
        if self._segment < 0:
            seg, t, point = project_on_path(path[:, :2], position, 0, last)
        else:
            limit = self._s[self._segment] + reach
            end = min(last, max(int(np.searchsorted(self._s, limit, side="right")),
                                self._segment + 1))
            seg, t, point = project_on_path(path[:, :2], position, self._segment, end)
        self._segment = seg
        s0 = self._s[seg] + t * (self._s[min(seg + 1, last)] - self._s[seg])
        end = min(last, int(np.searchsorted(self._s, s0 + reach, side="right")))
        xy = np.vstack((point[None, :], path[seg + 1 : end + 1, :2]))
        yaw = np.concatenate(([path[min(seg + 1, last), 2]], path[seg + 1 : end + 1, 2]))
        s = np.concatenate(([0.0], self._s[seg + 1 : end + 1] - s0))
        return xy, yaw, s, end == last

    # -- one cycle -----------------------------------------------------------------------------
    def compute(
        self,
        pose: tuple[float, float, float],
        path_xy_yaw: np.ndarray,
        elapsed: float,
        limits: RobotLimits,
        xy_tolerance: float,
        yaw_tolerance: float,
        costmap: Costmap2D | None = None,
        path_key: Any = None,
        robot_radius: float = 0.0,
    ) -> MppiCommand:
        """The command for this cycle; ``elapsed`` is the time since the previous one (s);
        ``robot_radius`` (m) is the disc kept, with the margin, off obstacle cells."""
        p = self.params
        if len(path_xy_yaw) == 0:
            self.reset()
            return MppiCommand()
        steps = p["horizon_steps"]
        if self.sequence.shape[0] != steps:
            self.reset()
        key = path_key if path_key is not None else id(path_xy_yaw)
        # Identity for path objects (a Path compares its poses field by field); value for ints.
        if not (key is self._path_key or (type(key) is int and key == self._path_key)):
            old_goal = self._path[-1] if len(self._path) else None
            self._path_key = key
            self._path = densify_path(path_xy_yaw)
            lengths = np.hypot(*np.diff(self._path[:, :2], axis=0).T)
            self._s = np.concatenate(([0.0], np.cumsum(lengths)))
            self._segment = -1
            # A new goal cancels a turn to a free heading; a replanned path to the same goal
            # does not (the costmap and NavMap planners plan anew each cycle by default: the
            # robot would never count as stuck for a second).
            if old_goal is None or not np.allclose(old_goal, self._path[-1], atol=1e-3):
                self._forget_free_heading()
        x0, y0, yaw0 = pose
        dt = p["dt"]
        max_v = max(limits.max_linear_vel, 0.0)
        max_w = max(limits.max_angular_vel, 0.0)
        goal = tuple(float(v) for v in self._path[-1])
        goal_dist = math.hypot(goal[0] - x0, goal[1] - y0)
        # The end of the approach (turn to the goal's yaw, arrive only within the goal
        # manager's tolerance, creep when turned beyond it): GoalArrival decides.
        was_turning = self.arrival.turning
        action = self.arrival.decide(pose, goal, xy_tolerance, yaw_tolerance,
                                     can_reverse=limits.min_linear_vel < 0.0)
        if action is not None:
            self.sequence[:] = 0.0
            self._forget_free_heading()
            kind, value = action
            if kind == TURN:
                if not was_turning:  # a new turn: not the way a turn to the path went
                    self._rotation_sign, self._rotating = 0.0, False
                error = self._latch(value)
                w = rotation_speed(error, self.last[1], elapsed, max_w, limits.max_angular_acc,
                                   limits.max_angular_decel, max_w)
                return self._apply(0.0, w, ROTATING_TO_GOAL)
            self._rotation_sign = 0.0
            if kind == CREEP:
                v = creep_command(value, self.last[0], elapsed, limits)
                return self._apply(v, 0.0, CREEPING_TO_GOAL)
            return self._apply(0.0, 0.0, ARRIVED)

        rollout_reach = max(max_v, abs(limits.min_linear_vel)) * steps * dt
        path_xy, path_yaw, path_s, is_final = self._local_path(
            np.array((x0, y0)), rollout_reach + PATH_MARGIN)
        if p["use_rotate_to_heading"]:
            angle, far = self._angle_to_path_ahead(pose, path_xy, path_yaw, path_s)
            threshold = p["rotate_to_heading_min_angle"] * (0.5 if self._rotating else 1.0)
            if far and abs(angle) > threshold:
                self._rotating = True
                self._forget_free_heading()
                angle = self._latch(angle)
                self.sequence[:] = 0.0
                w = rotation_speed(angle, self.last[1], elapsed, max_w, limits.max_angular_acc,
                                   limits.max_angular_decel, max_w)
                return self._apply(0.0, w, ROTATING_TO_HEADING)
        self._rotating = False
        self._rotation_sign = 0.0
        if self._free_heading is not None:
            if self.last[0] != 0.0:
                # Braking first, and easing any turn: the turn in place starts from a standstill.
                return self._apply(*self._braking(limits, elapsed), TURNING_TO_FREE_HEADING)
            # Through the path's direction (where the search started), never round the back:
            # the rotation to the path's heading would take over there and turn it back.
            error = (normalize_angle(self._free_heading - self._free_reference)
                     - normalize_angle(yaw0 - self._free_reference))
            if abs(error) > FREE_HEADING_TOLERANCE:
                w = rotation_speed(error, self.last[1], elapsed, max_w, limits.max_angular_acc,
                                   limits.max_angular_decel, max_w)
                return self._apply(0.0, w, TURNING_TO_FREE_HEADING)
            self._forget_free_heading()  # there: optimise again, from a cold start

        # Warm start: the previous optimal sequence, shifted by the time elapsed.
        shift = min(max(int(round(elapsed / dt)), 0), steps)
        if shift:
            self.sequence[:-shift] = self.sequence[shift:].copy()
            self.sequence[-shift:] = self.sequence[-shift - 1] if shift < steps else 0.0

        bounds = (
            min(limits.min_linear_vel, 0.0), max_v, max_w,
            limits.max_linear_acc, limits.max_linear_decel,
            limits.max_angular_acc, limits.max_angular_decel,
        )
        # Samples keep to the speed limits only: with independent noise per step, holding each
        # sample within a small acceleration window (0.5 m/s² is 0.025 m/s per 0.05 s step)
        # would leave almost no spread to choose from. The optimal sequence and the command
        # are held within the accelerations from the current command below.
        sample_bounds = bounds[:3] + (math.inf,) * 4
        std = np.array((p["vx_std"], p["wz_std"]), dtype=np.float32)
        # (Reaching at least as far as a free heading is checked, when the limits are low.)
        collision = None if costmap is None else CollisionModel(
            costmap, pose, max(rollout_reach, FREE_HEADING_DISTANCE), robot_radius,
            p["CostCritic.collision_margin"], p["CostCritic.consider_unknown_lethal"], path_xy,
            self._held)
        self._held = None if collision is None else collision.held
        batch = None
        for _ in range(p["iteration_count"]):
            # White noise per step averages out over the horizon (a 56-step sample ends within
            # a few centimetres of the mean); the constant part samples arcs that can look
            # round an obstacle, with the same variance per step.
            noise = self.noise.take(p["constant_noise_ratio"])
            vx = noise[0]
            vx *= std[0]
            vx += self.sequence[:, 0]
            wz = noise[1]
            wz *= std[1]
            wz += self.sequence[:, 1]
            x, y, yaw = constrain_and_integrate(vx, wz, pose, self.last, dt, sample_bounds)
            batch = MppiBatch(
                vx, wz, x, y, yaw, np.zeros(len(vx), dtype=np.float32), dt, pose, self.last,
                limits, path_xy, path_yaw, path_s, is_final, goal, goal_dist, costmap,
                collision,
            )
            for critic in self.critics:
                critic.score(batch)
            if p["gamma"] > 0.0:
                # Nav2's control cost: γ·u·Σ⁻¹·ε with the noise as it is after the limits.
                gamma = np.float32(p["gamma"]) / (std * std)
                batch.costs += gamma[0] * ((vx - self.sequence[:, 0]) @ self.sequence[:, 0])
                batch.costs += gamma[1] * ((wz - self.sequence[:, 1]) @ self.sequence[:, 1])
            costs = batch.costs - batch.costs.min()
            weights = np.exp(-costs / np.float32(p["lambda"]))
            weights /= weights.sum()
            self.sequence[:, 0] = weights @ vx
            self.sequence[:, 1] = weights @ wz
        if p["use_smoothing"]:
            self.sequence = smooth_sequence(self.sequence, self.history)
        # The smoothed sequence within the limits again (one "sample").
        v_seq = self.sequence[None, :, 0].copy()
        w_seq = self.sequence[None, :, 1].copy()
        ox, oy, oyaw = constrain_and_integrate(v_seq, w_seq, pose, self.last, dt, bounds)
        state = FOLLOWING
        # The guard looks as far ahead as the robot needs to brake from full speed, plus
        # GUARD_REACTION: the weighted mean of samples that turn round an obstacle at different
        # times turns earlier than any of them and, seconds ahead, cuts the obstacle's corner.
        # Refusing it for that held a robot between the TurtleBot3 sandbox's pillars at a
        # crawl (fallback to the best sample, accelerating 0.025 m/s a cycle, the mean refused
        # again); the next cycles optimise again before the robot gets there.
        # (From the current speed when it is higher: a speed zone may just have lowered max_v.)
        braking = max(max_v, abs(self.last[0])) / max(limits.max_linear_decel, 1e-3)
        guard = min(steps, max(1, math.ceil((braking + GUARD_REACTION) / dt)))
        if collision is not None and collision.rollout_collides(ox[0, :guard], oy[0, :guard]):
            # The weighted mean of collision-free samples (two ways round an obstacle) may
            # itself collide: fall back to the best sample, held within the accelerations.
            best = int(np.argmin(batch.costs))
            v_seq = batch.vx[best][None].copy()
            w_seq = batch.wz[best][None].copy()
            ox, oy, oyaw = constrain_and_integrate(v_seq, w_seq, pose, self.last, dt, bounds)
            if collision.rollout_collides(ox[0, :guard], oy[0, :guard]):
                # Nothing safe in reach: brake and start the next optimisation afresh.
                self.sequence[:] = 0.0
                self.last_batch = batch
                v = self._braking(limits, elapsed)[0]
                w = 0.0
                if v == 0.0:
                    # Stopped: turn on the spot towards the path ahead (a disc turning in place
                    # touches nothing). A robot stopped facing an obstacle beside its path
                    # finds every sample colliding (each drives some way ahead first) and,
                    # not turning, stayed blocked for good: seen against a pillar of the
                    # TurtleBot3 sandbox. Latched near ±pi, as the other turns in place.
                    angle, _far = self._angle_to_path_ahead(pose, path_xy, path_yaw, path_s)
                    angle = latched_angle(angle, self._blocked_sign)
                    self._blocked_sign = 1.0 if angle >= 0.0 else -1.0
                    w = rotation_speed(angle, self.last[1], elapsed, max_w,
                                       limits.max_angular_acc, limits.max_angular_decel, max_w)
                self._stuck_time = 0.0  # blocked has its own turn
                return self._apply(v, w, BLOCKED)
            self._blocked_sign = 0.0
            state = FALLBACK
        else:
            self._blocked_sign = 0.0
        self.last_batch = batch
        if self._stuck(pose, v_seq[0], max_v, elapsed, collision, batch.remaining,
                       xy_tolerance):
            found = self._free_heading_towards_path(pose, path_xy, path_yaw, path_s, collision)
            self._stuck_time = 0.0  # no turn found: look again after another second
            if found is not None and abs(normalize_angle(found[0] - yaw0)) > (
                    FREE_HEADING_TOLERANCE):
                self._free_heading, self._free_reference = found
                self.sequence[:] = 0.0
                return self._apply(*self._braking(limits, elapsed), TURNING_TO_FREE_HEADING)
        self.sequence[:, 0] = v_seq[0]
        self.sequence[:, 1] = w_seq[0]
        optimal = np.column_stack((ox[0], oy[0], oyaw[0]))
        return self._apply(float(v_seq[0, 0]), float(w_seq[0, 0]), state, optimal)

    def _angle_to_path_ahead(self, pose, path_xy, path_yaw, path_s) -> tuple[float, bool]:
        """The angle from the robot's heading to the local-path point
        ``rotate_to_heading_lookahead_dist`` ahead (to the path's yaw at the robot when that
        point is the robot's own position), and whether the point is away from the robot."""
        x0, y0, yaw0 = pose
        ahead = min(int(np.searchsorted(path_s, self.params["rotate_to_heading_lookahead_dist"])),
                    len(path_xy) - 1)
        tx, ty = path_xy[ahead]
        if math.hypot(tx - x0, ty - y0) > 1e-3:
            return normalize_angle(math.atan2(ty - y0, tx - x0) - yaw0), True
        return normalize_angle(path_yaw[0] - yaw0), False

    def _braking(self, limits: RobotLimits, elapsed: float) -> tuple[float, float]:
        """The last command eased towards a standstill within the decelerations."""
        v, w = self.last
        v = max(0.0, v - limits.max_linear_decel * elapsed) if v > 0.0 else min(
            0.0, v + limits.max_linear_decel * elapsed)
        return v, math.copysign(max(0.0, abs(w) - limits.max_angular_decel * elapsed), w)

    def _forget_free_heading(self) -> None:
        self._free_heading: float | None = None  # the yaw turned to when stuck
        self._free_reference = 0.0  # the path's direction it turns through
        self._stuck_time = 0.0  # how long the robot has been stuck (s)

    @staticmethod
    def _straight_collides(pose, heading: float, collision: CollisionModel) -> bool:
        """Whether driving :data:`FREE_HEADING_DISTANCE` straight along ``heading`` from
        ``pose`` collides (``collision``)."""
        along = np.linspace(0.0, FREE_HEADING_DISTANCE, 13)[1:]
        x = (pose[0] + along * math.cos(heading)).astype(np.float32)
        y = (pose[1] + along * math.sin(heading)).astype(np.float32)
        return collision.rollout_collides(x, y)

    def _stuck(self, pose, v_seq: np.ndarray, max_v: float, elapsed: float,
               collision: CollisionModel | None, remaining: float, xy_tolerance: float) -> bool:
        """Whether the robot has been stuck for :data:`STUCK_TIME` (see
        :data:`STUCK_SPEED_RATIO`), counting this cycle; not near the goal, where a robot
        slows down on purpose."""
        if (collision is None or remaining <= xy_tolerance + FREE_HEADING_DISTANCE
                or float(np.abs(v_seq).mean()) >= STUCK_SPEED_RATIO * max_v
                or not self._straight_collides(pose, pose[2], collision)):
            self._stuck_time = 0.0
            return False
        self._stuck_time += elapsed
        return self._stuck_time >= STUCK_TIME

    def _free_heading_towards_path(self, pose, path_xy, path_yaw, path_s,
                                   collision: CollisionModel) -> tuple[float, float] | None:
        """The heading nearest the direction to the path point
        ``rotate_to_heading_lookahead_dist`` ahead along which the robot can drive
        :data:`FREE_HEADING_DISTANCE` straight without colliding (``collision``), tried every
        ``2π / FREE_HEADINGS``, on the side the robot faces first at equal angles, and that
        direction; None when none is free. With ``use_rotate_to_heading``, only headings the
        rotation to the path's heading would not turn the robot back from (within
        ``rotate_to_heading_min_angle``, less twice :data:`FREE_HEADING_TOLERANCE`): with one
        it would, in a corner, the two would turn the robot back and forth for good."""
        angle, _far = self._angle_to_path_ahead(pose, path_xy, path_yaw, path_s)
        wanted = pose[2] + angle
        widest = math.pi
        if self.params["use_rotate_to_heading"]:
            widest = self.params["rotate_to_heading_min_angle"] - 2.0 * FREE_HEADING_TOLERANCE
        toward_yaw = -1.0 if angle > 0.0 else 1.0  # the robot's heading is on this side
        step = 2.0 * math.pi / FREE_HEADINGS
        for k in range(FREE_HEADINGS // 2 + 1):
            if k * step > widest:
                break
            for sign in (toward_yaw, -toward_yaw) if 0 < k < FREE_HEADINGS // 2 else (1.0,):
                heading = wanted + sign * k * step
                if not self._straight_collides(pose, heading, collision):
                    return normalize_angle(heading), normalize_angle(wanted)
        return None

    def _latch(self, angle: float) -> float:
        # Keep turning the way a rotation in place started while the target is near ±π.
        angle = latched_angle(angle, self._rotation_sign)
        self._rotation_sign = 1.0 if angle >= 0.0 else -1.0
        return angle

    def _apply(self, v: float, w: float, state: str, optimal=None) -> MppiCommand:
        self.last = (v, w)
        self.history = np.vstack((self.history, np.array([[v, w]], dtype=np.float32)))[-HISTORY:]
        return MppiCommand(v, w, state, optimal)
