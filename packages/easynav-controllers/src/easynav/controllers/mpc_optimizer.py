"""MPCOptimizer: the original MPC's cost over a short horizon, minimised with scipy."""

from __future__ import annotations

import math

import numpy as np

#: scipy.optimize.minimize methods used (bounded, gradient-based). The original's COBYLA is not
#: offered: scipy's costs about 1 ms per evaluation here (150 ms a cycle for the default horizon).
SOLVERS = ("SLSQP", "L-BFGS-B")


def wrap_angle(angle):
    """Angles (scalar or array) wrapped to [-pi, pi)."""
    return (np.asarray(angle) + math.pi) % (2.0 * math.pi) - math.pi


class MPCOptimizer:
    """The cost of the original ``MPCOptimizer`` and its minimisation.

    Decision variables: ``N = horizon_steps`` pairs ``(v_k, w_k)``. For each step the unicycle
    model predicts a pose ``x_k``; the cost is

        sum_k  q_pos * |goal - p_k|^2 + q_theta * (bearing(goal - p_k) - yaw_k)^2
               + r_effort * (v_k^2 + w_k^2) + r_smooth * ((v_k+1 - v_k)^2 + (w_k+1 - w_k)^2)

    with the original's weights (4, 3, 0.1, 0.1). As in the original, each step is predicted from
    the **current** pose (``chained=False``); ``chained=True`` chains the predictions (step k
    starts where step k-1 ended), the textbook model. The bearing error is wrapped to [-pi, pi)
    (the original's unwrapped difference made the robot turn the long way when the bearing
    crossed +-pi).

    Thread contract: an instance is used by one thread at a time. Exceptions: ``ValueError`` for
    a bad horizon, step or solver; ``ImportError`` naming the extra when scipy is missing
    (raised by :meth:`solve`).
    """

    def __init__(
        self,
        horizon_steps: int = 5,
        dt: float = 0.1,
        chained: bool = False,
        solver: str = "SLSQP",
        weights: tuple[float, float, float, float] = (4.0, 3.0, 0.1, 0.1),
        tolerance: float = 1e-3,
    ) -> None:
        if horizon_steps < 1:
            raise ValueError(f"horizon_steps = {horizon_steps} must be >= 1")
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"dt = {dt} must be finite and > 0")
        if solver not in SOLVERS:
            raise ValueError(f"solver = {solver!r} must be one of {', '.join(SOLVERS)}")
        self.horizon_steps = int(horizon_steps)
        self.dt = float(dt)
        self.chained = bool(chained)
        self.solver = solver
        self.q_pos, self.q_theta, self.r_effort, self.r_smooth = (float(w) for w in weights)
        self.tolerance = float(tolerance)

    def predict(self, u: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
        """Predicted poses ``(N, 3)`` (x, y, yaw) after each step of ``u`` ``(N, 2)``."""
        u = np.asarray(u, dtype=float).reshape(-1, 2)
        x0, y0, yaw0 = pose
        v, w = u[:, 0], u[:, 1]
        dt = self.dt
        if self.chained:
            yaw_after = yaw0 + dt * np.cumsum(w)
            heading = np.concatenate(([yaw0], yaw_after[:-1]))
            x = x0 + dt * np.cumsum(v * np.cos(heading))
            y = y0 + dt * np.cumsum(v * np.sin(heading))
        else:
            yaw_after = yaw0 + dt * w
            x = x0 + dt * v * math.cos(yaw0)
            y = y0 + dt * v * math.sin(yaw0)
        return np.column_stack((x, y, yaw_after))

    def cost(self, u: np.ndarray, pose: tuple[float, float, float], goal: tuple[float, float]):
        """The cost of the flat control vector ``u`` (v0, w0, v1, w1, ...)."""
        u = np.asarray(u, dtype=float).reshape(-1, 2)
        states = self.predict(u, pose)
        ex = goal[0] - states[:, 0]
        ey = goal[1] - states[:, 1]
        e_theta = wrap_angle(np.arctan2(ey, ex) - states[:, 2])
        du = np.diff(u, axis=0)
        return float(
            self.q_pos * np.sum(ex * ex + ey * ey)
            + self.q_theta * np.sum(e_theta * e_theta)
            + self.r_effort * np.sum(u * u)
            + self.r_smooth * np.sum(du * du)
        )

    def gradient(self, u: np.ndarray, pose: tuple[float, float, float], goal):
        """The cost's analytic gradient with respect to the flat ``u`` (both models)."""
        u = np.asarray(u, dtype=float).reshape(-1, 2)
        dt = self.dt
        v, w = u[:, 0], u[:, 1]
        states = self.predict(u, pose)
        ex = goal[0] - states[:, 0]
        ey = goal[1] - states[:, 1]
        e_theta = wrap_angle(np.arctan2(ey, ex) - states[:, 2])
        r2 = np.maximum(ex * ex + ey * ey, 1e-12)
        # Cost sensitivity to each predicted position (x_k, y_k), tracking and bearing terms.
        a = -2.0 * self.q_pos * ex + 2.0 * self.q_theta * e_theta * ey / r2
        b = -2.0 * self.q_pos * ey - 2.0 * self.q_theta * e_theta * ex / r2
        grad = np.empty_like(u)
        if self.chained:
            heading = pose[2] + dt * np.concatenate(([0.0], np.cumsum(w)[:-1]))
            c, s = np.cos(heading), np.sin(heading)
            # x_k, y_k depend on v_j (j <= k) through heading_j; on w_j through every later
            # heading; yaw_k on every w_j (j <= k).
            ra = np.cumsum(a[::-1])[::-1]
            rb = np.cumsum(b[::-1])[::-1]
            grad[:, 0] = dt * (c * ra + s * rb)
            p = dt * dt * v * (c * rb - s * ra)
            later = np.concatenate((np.cumsum(p[::-1])[::-1][1:], [0.0]))
            yaw_term = -2.0 * self.q_theta * dt * np.cumsum(e_theta[::-1])[::-1]
            grad[:, 1] = later + yaw_term
        else:
            c, s = math.cos(pose[2]), math.sin(pose[2])
            grad[:, 0] = dt * (a * c + b * s)
            grad[:, 1] = -2.0 * self.q_theta * e_theta * dt
        grad += 2.0 * self.r_effort * u
        du = np.diff(u, axis=0)
        grad[:-1] -= 2.0 * self.r_smooth * du
        grad[1:] += 2.0 * self.r_smooth * du
        return grad.ravel()

    def solve(
        self,
        pose: tuple[float, float, float],
        goal: tuple[float, float],
        low: np.ndarray,
        high: np.ndarray,
        initial: np.ndarray | None = None,
    ) -> np.ndarray:
        """The minimising controls ``(N, 2)`` within ``low <= u <= high`` (each ``(N, 2)``).

        ``initial`` (``(N, 2)``, e.g. the previous solution shifted by one step) is the warm
        start, clipped into the bounds; zeros when None (the original's start). The result is
        clipped into the bounds.
        """
        try:
            from scipy.optimize import minimize
        except ImportError as exc:  # pragma: no cover - depends on the installation
            raise ImportError(
                "MPCController needs scipy: pip install 'easynav-controllers[mpc]'"
            ) from exc
        n = self.horizon_steps
        low = np.broadcast_to(np.asarray(low, dtype=float), (n, 2)).ravel()
        high = np.broadcast_to(np.asarray(high, dtype=float), (n, 2)).ravel()
        x0 = np.zeros(2 * n) if initial is None else np.asarray(initial, dtype=float).ravel()
        x0 = np.clip(x0, low, high)
        result = minimize(
            self.cost,
            x0,
            args=(tuple(pose), tuple(goal)),
            method=self.solver,
            jac=self.gradient,
            bounds=list(zip(low, high, strict=True)),
            options={"maxiter": 200},
            tol=self.tolerance,
        )
        u = result.x if np.all(np.isfinite(result.x)) else x0
        return np.clip(u, low, high).reshape(n, 2)
