"""SerestTracker: the SeReST path tracker of the original, without ROS."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from easynav.controllers.command_limits import limit_command
from easynav.core.robot import RobotLimits

#: Defaults of the original (``SerestController.hpp``), by parameter name.
SEREST_DEFAULTS: dict[str, Any] = {
    "allow_reverse": False, "v_progress_min": 0.05, "k_s_share_max": 0.5,
    "k_s": 0.8, "k_theta": 2.0, "k_y": 1.2, "ell": 0.3, "v_ref": 0.6, "eps": 1e-3,
    "a_acc": 0.8, "a_brake": 1.2, "a_lat_max": 1.5, "d0_margin": 0.30, "tau_latency": 0.10,
    "d_hard": 0.20, "t_emerg": 0.25, "blend_base": 0.6, "blend_k_per_v": 0.6, "kappa_max": 2.5,
    "dist_search_radius": 2.0, "goal_pos_tol": 0.05, "goal_yaw_tol_deg": 5.0,
    "slow_radius": 0.60, "slow_min_speed": 0.03, "final_align_k": 2.0, "final_align_wmax": 0.6,
    "corner_guard_enable": True, "corner_gain_ey": 1.5, "corner_gain_eth": 0.7,
    "corner_gain_kappa": 0.4, "corner_min_alpha": 0.35, "corner_boost_omega": 0.8,
    "apex_ey_des": 0.05, "a_lat_soft": 1.1,
}

#: Turn in place above 60 degrees of heading error; leave it below 35 (the original's constants).
TIP_ENTER = math.radians(60.0)
TIP_EXIT = math.radians(35.0)
NEAR_START_S = 0.30
ALIGN_CRUISE = math.radians(30.0)
#: Half the arc (m) over which the path's own curvature is measured (see :meth:`step`).
CURVATURE_HALF_WINDOW = 0.15
#: Spacing (m) of the points ahead where :meth:`SerestTracker.turn_speed_ahead` looks.
TURN_PROBE_STEP = 0.05
#: Consecutive path poses closer than this (m) count as one.
MIN_STEP = 1e-4

#: Phases reported in :attr:`SerestOutput.state`.
TRACKING, TURN_IN_PLACE, FINAL_ALIGN, ARRIVED, EMERGENCY = (
    "tracking", "turn_in_place", "final_align", "arrived", "emergency",
)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


@dataclass
class SerestOutput:
    """One step's command, phase and the original's debug values (``serest.debug.*``)."""

    v: float
    w: float
    state: str
    debug: dict[str, float] = field(default_factory=dict)


class SerestTracker:
    """Safe reference tracking (SeReST) of a polyline, step by step.

    Projects the robot on the path, blends heading and curvature around vertices (logistic over
    ``blend_base + blend_k_per_v * |v|`` metres), computes the Frenet errors and the command::

        s_dot = cos(e_theta) * v_ref' / (1 - kappa * e_y) - k_s * e_y   (capped)
        w     = kappa * s_dot - k_theta * e_theta - k_y * atan(e_y / ell)  (+ corner guard)

    with ``v_ref'`` limited by curvature, by the speed that stops before the closest obstacle
    (``sqrt(2 a_brake (d - d0_margin)) - tau_latency a_brake``) and scaled down in the slow zone
    near the goal. It turns in place above 60 degrees of heading error, stops and turns to the
    goal yaw within the position tolerance, brakes on an emergency (``d <= d_hard`` or
    ``d / |v| <= t_emerg``), then rate-limits and saturates with the limits given.

    ``params`` is any mapping with the names of :data:`SEREST_DEFAULTS` (a plugin passes its
    ``ParameterValues``): it is read at every step, so a change takes effect at once.

    Differences from the original: the stop zone is checked before turning in place, and a goal
    yaw far from the last segment's heading no longer asks for a turn in place (in the original
    the robot then stopped short of the goal for good); within ``slow_radius`` of the goal (and
    of the path's end) the reference heading is the bearing to the goal (the original drove on
    past the end when it reached it beside the path); a path of one pose is followed from the
    robot's position; repeated poses are skipped; the goal manager's tolerances are used.

    Thread contract: one thread at a time (it keeps the previous command). Exceptions: none for
    finite input; ``ValueError`` for an empty path.
    """

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        self.params: Mapping[str, Any] = dict(SEREST_DEFAULTS) if params is None else params
        self.last_v = 0.0
        self.last_w = 0.0
        self.tip_active = False

    def reset(self) -> None:
        """Forget the previous command and the turn-in-place phase."""
        self.last_v = 0.0
        self.last_w = 0.0
        self.tip_active = False

    # -- geometry -------------------------------------------------------------------------------
    @staticmethod
    def _clean(path_xy: np.ndarray, position: tuple[float, float]) -> np.ndarray:
        pts = np.asarray(path_xy, dtype=float)[:, :2]
        if len(pts) == 0:
            raise ValueError("SeReST: the path is empty")
        keep = np.ones(len(pts), dtype=bool)
        # Poses closer than MIN_STEP are one: a heading between two nearly equal poses is noise
        # (a turn of arbitrary sign, capped at kappa_max, in the path's curvature).
        keep[1:] = np.hypot(*(np.diff(pts, axis=0).T)) > MIN_STEP
        pts = pts[keep]
        if len(pts) == 1:
            pts = np.vstack((np.asarray(position, dtype=float), pts))
            if np.hypot(*(pts[1] - pts[0])) <= 1e-9:
                pts[0] -= (1e-6, 0.0)
        return pts

    @staticmethod
    def project(pts: np.ndarray, s_acc: np.ndarray, p: np.ndarray) -> tuple[int, np.ndarray, float]:
        """``(segment index, closest point, arc length s*)`` of ``p`` on the polyline."""
        a, b = pts[:-1], pts[1:]
        ab = b - a
        ab2 = np.einsum("ij,ij->i", ab, ab)
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(ab2, 1e-12), 0.0, 1.0)
        q = a + ab * t[:, None]
        d2 = np.einsum("ij,ij->i", p - q, p - q)
        i = int(np.argmin(d2))
        return i, q[i], float(s_acc[i] + t[i] * math.sqrt(ab2[i]))

    def reference(self, pts, s_acc, seg: int, s_star: float, v_prev: float):
        """``(psi_ref, kappa_hat)``: heading and curvature blended around the segment's ends."""
        p = self.params
        n = len(pts)

        def heading(i: int) -> float:
            d = pts[i + 1] - pts[i]
            return math.atan2(d[1], d[0])

        b = max(0.1, p["blend_base"] + p["blend_k_per_v"] * abs(v_prev))
        psi_i = heading(seg)
        psi_ref, kappa = psi_i, 0.0
        kappa_max = p["kappa_max"]
        if seg > 0 and (s_star - s_acc[seg]) < b:
            psi_prev = heading(seg - 1)
            w = 1.0 / (1.0 + math.exp(-(s_star - s_acc[seg]) / b))
            psi_ref = math.atan2(
                (1 - w) * math.sin(psi_prev) + w * math.sin(psi_i),
                (1 - w) * math.cos(psi_prev) + w * math.cos(psi_i),
            )
            kappa = min(max(_wrap(psi_i - psi_prev) * w * (1 - w) / b, -kappa_max), kappa_max)
        if seg + 1 < n - 1 and (s_acc[seg + 1] - s_star) < b:
            psi_next = heading(seg + 1)
            w = 1.0 / (1.0 + math.exp(-(s_acc[seg + 1] - s_star) / b))
            psi_ref = math.atan2(
                (1 - w) * math.sin(psi_i) + w * math.sin(psi_next),
                (1 - w) * math.cos(psi_i) + w * math.cos(psi_next),
            )
            k2 = min(max(_wrap(psi_next - psi_i) * w * (1 - w) / b, -kappa_max), kappa_max)
            kappa = 0.5 * (kappa + k2)
        return psi_ref, kappa

    @staticmethod
    def path_curvature(pts: np.ndarray, s_acc: np.ndarray, s_star: float, half: float) -> float:
        """The path's mean curvature (1/m, signed) over ``[s_star - half, s_star + half]`` of
        arc length (clipped to the path); see :meth:`path_curvatures`."""
        return float(SerestTracker.path_curvatures(pts, s_acc, np.array([s_star]), half)[0])

    @staticmethod
    def path_curvatures(pts: np.ndarray, s_acc: np.ndarray, s: np.ndarray,
                        half: float) -> np.ndarray:
        """The path's mean curvature (1/m, signed) over ``[s - half, s + half]`` of arc length
        (clipped to the path), for each arc length in ``s``.

        Each vertex's turn is spread evenly over the arc around it, up to ``half`` or half its
        segments each side, and a window takes its share of every spread turn: on an arc
        sampled every 0.1-0.2 m, counting only the vertices inside the window made the
        curvature jump by a third or more as vertices came in and out of it; a lone sharp
        corner ramps up and down over ``2·half`` instead of stepping."""
        s = np.asarray(s, dtype=float)
        n = len(pts)
        lo = np.clip(s - half, 0.0, s_acc[-1])
        hi = np.clip(s + half, 0.0, s_acc[-1])
        out = np.zeros(len(s))
        if n < 3 or len(s) == 0:
            return out
        # The inner vertices whose spread can reach a window.
        first = max(int(np.searchsorted(s_acc, lo.min() - half, side="left")), 1)
        end = min(int(np.searchsorted(s_acc, hi.max() + half, side="right")), n - 1)
        if end <= first:
            return out
        k = np.arange(first, end)
        d_in = pts[k] - pts[k - 1]
        d_out = pts[k + 1] - pts[k]
        turn = np.arctan2(d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0],
                          np.einsum("ij,ij->i", d_in, d_out))
        before = np.minimum(0.5 * (s_acc[k] - s_acc[k - 1]), half)
        after = np.minimum(0.5 * (s_acc[k + 1] - s_acc[k]), half)
        overlap = np.clip(np.minimum((s_acc[k] + after)[None, :], hi[:, None])
                          - np.maximum((s_acc[k] - before)[None, :], lo[:, None]), 0.0, None)
        captured = overlap / np.maximum(before + after, 1e-9) @ turn
        width = hi - lo
        np.divide(captured, width, out=out, where=width > 1e-6)
        return out

    def turn_speed_ahead(self, pts: np.ndarray, s_acc: np.ndarray, s_star: float,
                         limits: RobotLimits) -> float:
        """The fastest speed from which the robot can brake (``max_linear_decel``) to the
        curvature speed of every turn of the path within its braking distance (plus
        :data:`CURVATURE_HALF_WINDOW`) ahead of ``s_star``; inf when none is that close. The
        curvature at the projection alone left a robot at 1 m/s 0.15 m to shed its speed
        before a densely sampled right angle: it overshot by 0.44 m."""
        probes = self._turn_probes(s_acc, s_star, limits)
        curvatures = self.path_curvatures(pts, s_acc, probes, CURVATURE_HALF_WINDOW)
        return self._speed_before_turns(probes, curvatures, s_star, limits)

    def _turn_probes(self, s_acc: np.ndarray, s_star: float, limits: RobotLimits) -> np.ndarray:
        """Arc lengths ahead of ``s_star`` where :meth:`turn_speed_ahead` looks."""
        decel = max(0.1, limits.max_linear_decel)
        reach = self.last_v ** 2 / (2.0 * decel) + CURVATURE_HALF_WINDOW
        probes = s_star + np.arange(TURN_PROBE_STEP, reach + 1e-9, TURN_PROBE_STEP)
        return probes[probes < s_acc[-1]]

    def _speed_before_turns(self, probes: np.ndarray, curvatures: np.ndarray, s_star: float,
                            limits: RobotLimits) -> float:
        """:meth:`turn_speed_ahead` from the path's curvatures at ``probes``."""
        p = self.params
        curv = np.minimum(np.abs(curvatures), p["kappa_max"])
        tight = curv > 1e-6
        if not tight.any():
            return math.inf
        decel = max(0.1, limits.max_linear_decel)
        v_turn = np.minimum(limits.max_angular_vel / curv[tight],
                            np.sqrt(p["a_lat_soft"] / curv[tight]))
        return float(np.min(np.sqrt(v_turn ** 2 + 2.0 * decel * (probes[tight] - s_star))))

    def v_safe(self, d: float) -> float:
        """The speed that stops ``d0_margin`` short of an obstacle ``d`` metres away."""
        p = self.params
        a = max(0.1, p["a_brake"])
        if d <= p["d0_margin"]:
            return 0.0
        if math.isinf(d):
            return math.inf
        return max(0.0, math.sqrt(2.0 * a * (d - p["d0_margin"])) - p["tau_latency"] * a)

    # -- one step -------------------------------------------------------------------------------
    def step(
        self,
        path_xy_yaw: np.ndarray,
        pose: tuple[float, float, float],
        dt: float,
        limits: RobotLimits,
        d_closest: float = math.inf,
        pos_tol: float | None = None,
        yaw_tol: float | None = None,
    ) -> SerestOutput:
        """The command for the robot at ``pose`` (x, y, yaw) on the path ``(N, 3)``.

        ``limits``: the limits in force (speeds, accelerations). ``pos_tol`` / ``yaw_tol``: the
        goal manager's tolerances; None uses ``goal_pos_tol`` / ``goal_yaw_tol_deg``.
        """
        p = self.params
        rev = bool(p["allow_reverse"])
        max_v = limits.max_linear_vel
        max_w = limits.max_angular_vel
        if pos_tol is None:
            pos_tol = p["goal_pos_tol"]
        if yaw_tol is None:
            yaw_tol = math.radians(p["goal_yaw_tol_deg"])
        path_xy_yaw = np.asarray(path_xy_yaw, dtype=float)
        robot = np.array(pose[:2], dtype=float)
        yaw = pose[2]
        pts = self._clean(path_xy_yaw, pose[:2])
        s_acc = np.concatenate(([0.0], np.cumsum(np.hypot(*(np.diff(pts, axis=0).T)))))
        seg, closest, s_star = self.project(pts, s_acc, robot)
        psi_ref, kappa = self.reference(pts, s_acc, seg, s_star, self.last_v)
        # The original's curvature blends the turns at the current segment's two vertices only:
        # on a densely sampled path (a sampling planner's, a smoothed one), which turns a few
        # degrees at each of many vertices, it sees a fraction of the turn (0.08 1/m where an
        # OMPL path turned 97 degrees in 0.5 m), and the robot ran wide into a pillar. The
        # path's own turn around the robot's projection is the floor.
        # One computation for the projection and the turns ahead (turn_speed_ahead's probes).
        probes = self._turn_probes(s_acc, s_star, limits)
        curvatures = self.path_curvatures(pts, s_acc, np.concatenate(([s_star], probes)),
                                          CURVATURE_HALF_WINDOW)
        own = float(curvatures[0])
        if abs(own) > abs(kappa):
            kappa = min(max(own, -p["kappa_max"]), p["kappa_max"])
        normal = np.array((-math.sin(psi_ref), math.cos(psi_ref)))
        e_y = float(np.dot(robot - closest, normal))
        e_theta = _wrap(yaw - psi_ref)
        ell = max(p["ell"], 1e-3)

        goal = path_xy_yaw[-1]
        dist_goal = math.hypot(robot[0] - goal[0], robot[1] - goal[1])
        e_theta_goal = _wrap(yaw - goal[2]) if path_xy_yaw.shape[1] > 2 else 0.0
        stop_r = max(0.0, pos_tol)
        slow_r = max(p["slow_radius"], stop_r + 0.05)
        gamma_slow = 1.0
        if dist_goal < slow_r:
            gamma_slow = min(max((dist_goal - stop_r) / max(1e-3, slow_r - stop_r), 0.0), 1.0)
        dist_to_end = float(s_acc[-1] - s_star)
        homing = dist_goal < slow_r and dist_to_end < slow_r
        if homing and dist_goal > 1e-9:
            # Homing on the goal point: the path's tangent no longer leads there once the robot
            # is beside the end (the original drove on past the end, never entering the stop
            # zone, when it reached the end farther than the tolerance from the path).
            psi_ref, kappa, e_y = math.atan2(goal[1] - robot[1], goal[0] - robot[0]), 0.0, 0.0
            e_theta = _wrap(yaw - psi_ref)

        v_safe = self.v_safe(d_closest)
        ak = abs(kappa)
        v_curv = max_v
        if ak > 1e-6:
            v_curv = min(max_v, max_w / ak, math.sqrt(p["a_lat_soft"] / ak))
        if not homing:
            v_curv = min(v_curv, self._speed_before_turns(probes, curvatures[1:], s_star, limits))

        debug = {
            "e_y": e_y, "e_theta": e_theta, "kappa_hat": kappa, "d_closest": d_closest,
            "v_safe": v_safe, "v_curv": v_curv, "alpha": 1.0, "allow_reverse": int(rev),
            "dist_to_end": dist_to_end, "goal.dist_xy": dist_goal, "goal.gamma_slow": gamma_slow,
            "goal.in_final_align": 0, "goal.arrived": 0,
        }

        # Stop zone first: v = 0, turn to the goal yaw, arrived within the yaw tolerance.
        if dist_goal <= stop_r:
            self.tip_active = False
            if abs(e_theta_goal) <= yaw_tol:
                debug["goal.arrived"] = 1
                return self._out(0.0, 0.0, dt, limits, rev, ARRIVED, debug)
            debug["goal.in_final_align"] = 1
            wmax = p["final_align_wmax"]
            w = min(max(-p["final_align_k"] * e_theta_goal, -wmax), wmax)
            return self._out(0.0, w, dt, limits, rev, FINAL_ALIGN, debug)

        gamma_omega = max(0.25, gamma_slow)
        correction = -p["k_theta"] * e_theta - p["k_y"] * math.atan(e_y / ell)
        # Turn in place with hysteresis (kept only near the start of the path, as the original).
        request = self._tip_request(rev, e_theta)
        if not rev and s_star < NEAR_START_S and abs(e_theta) > TIP_ENTER:
            request = True
        if not self.tip_active and request and abs(e_theta) > TIP_ENTER:
            self.tip_active = True
        elif self.tip_active and (abs(e_theta) < TIP_EXIT or s_star > NEAR_START_S - 0.10):
            self.tip_active = False
        if self.tip_active:
            return self._out(0.0, correction * gamma_omega, dt, limits, rev, TURN_IN_PLACE, debug)

        cos_et = math.cos(e_theta)
        cos_pos = max(0.0, cos_et)
        denom = max(1e-3, 1.0 - kappa * e_y)
        v_free = min(max_v, v_curv, v_safe, p["v_ref"])
        v_prog = v_free * gamma_slow
        if not rev and abs(e_theta) < ALIGN_CRUISE:
            v_prog = max(v_prog, min(p["slow_min_speed"], v_free))
        v_prog, omega_boost, apex = self._corner_guard(kappa, e_y, e_theta, v_prog)
        forward = (abs(cos_et) if rev else cos_pos) * v_prog / denom
        cap = p["k_s_share_max"] * max(1e-3, forward)
        s_dot_nom = forward - min(max(p["k_s"] * e_y, -cap), cap)
        omega = (kappa * s_dot_nom + correction + apex) * omega_boost * gamma_omega

        alpha = min(1.0, v_safe / p["v_ref"]) if p["v_ref"] > 1e-6 else 1.0
        debug["alpha"] = alpha
        s_dot = alpha * s_dot_nom if rev else max(0.0, alpha * s_dot_nom)
        cos_for_v = max(1e-3, abs(cos_et) if rev else cos_pos)
        v_track = s_dot * denom / cos_for_v
        if rev:
            v_lim = min(v_curv, v_safe)
            v = min(max(v_track, -v_lim), v_lim)
        else:
            v = max(0.0, min(v_track, v_curv, v_safe, max_v))
        state = TRACKING
        if self._tip_request(rev, e_theta):
            v, omega, state = 0.0, correction * gamma_omega, TURN_IN_PLACE
        w = omega + kappa * (s_dot - s_dot_nom)
        if d_closest <= p["d_hard"] or d_closest / max(abs(self.last_v), 1e-3) <= p["t_emerg"]:
            step = p["a_brake"] * dt
            v = max(0.0, self.last_v - step) if self.last_v > 0 else min(0.0, self.last_v + step)
            w, state = 0.0, EMERGENCY
        return self._out(v, w, dt, limits, rev, state, debug)

    @staticmethod
    def _tip_request(rev: bool, e_theta: float) -> bool:
        # The original also asked for a turn in place within 0.5 m of the end when the goal yaw
        # was more than 60 degrees off; but that turn steers to the path, not the goal yaw, so
        # the robot stopped there for good. The goal yaw is the stop zone's business.
        return not rev and abs(e_theta) > TIP_ENTER

    def _corner_guard(self, kappa: float, e_y: float, e_theta: float, v_prog: float):
        p = self.params
        if not p["corner_guard_enable"]:
            return v_prog, 1.0, 0.0
        sgn = 1.0 if kappa >= 0.0 else -1.0
        e_out = max(0.0, sgn * e_y)
        penalty = (p["corner_gain_ey"] * e_out + p["corner_gain_eth"] * abs(e_theta)
                   + p["corner_gain_kappa"] * abs(kappa))
        alpha = min(max(1.0 / (1.0 + penalty), p["corner_min_alpha"]), 1.0)
        boost = 1.0 + p["corner_boost_omega"] * min(1.0, e_out / max(1e-3, p["ell"]))
        apex = 0.0
        if abs(kappa) > 1e-6 and e_out > 0.0:
            e_des = -sgn * max(0.0, p["apex_ey_des"])
            apex = -p["k_y"] * math.atan((e_y - e_des) / max(p["ell"], 1e-3))
        return v_prog * alpha, boost, apex

    def _out(self, v, w, dt, limits, rev, state, debug) -> SerestOutput:
        v, w = limit_command(v, w, self.last_v, self.last_w, dt, limits, allow_reverse=rev)
        self.last_v, self.last_w = v, w
        return SerestOutput(v, w, state, debug)
