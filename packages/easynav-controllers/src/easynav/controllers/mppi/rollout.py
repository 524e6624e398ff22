"""MPPI rollouts: controls held within the limits, then integrated as a unicycle.

:func:`constrain_and_integrate` is the fast path (numba when installed, else the numpy version);
:func:`constrain_and_integrate_reference` is the readable numpy version the tests compare with.
"""

from __future__ import annotations

import numpy as np


def constrain_and_integrate_reference(
    vx: np.ndarray,
    wz: np.ndarray,
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    dt: float,
    bounds: tuple[float, float, float, float, float, float, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clamp ``vx``, ``wz`` (S×T, in place) to the limits and integrate the rollouts.

    ``bounds = (min_v, max_v, max_w, v_acc, v_dec, w_acc, w_dec)``. Step t's speed lies within
    ``dt`` times the acceleration (speeding up, away from zero) or deceleration (slowing down)
    of step t−1's, step 0's of the current ``velocity``. The pose after step t:
    ``yaw_t = yaw_{t−1} + wz_t·dt``, ``x_t = x_{t−1} + vx_t·cos(yaw_{t−1})·dt`` (likewise y).
    Returns ``(x, y, yaw)`` (S×T, the dtype of ``vx``).
    """
    min_v, max_v, max_w, v_acc, v_dec, w_acc, w_dec = bounds
    np.clip(vx, min_v, max_v, out=vx)
    np.clip(wz, -max_w, max_w, out=wz)
    prev_v = np.full(vx.shape[0], velocity[0], dtype=vx.dtype)
    prev_w = np.full(vx.shape[0], velocity[1], dtype=vx.dtype)
    for t in range(vx.shape[1]):
        for values, prev, acc, dec in ((vx, prev_v, v_acc, v_dec), (wz, prev_w, w_acc, w_dec)):
            high = prev + np.where(prev >= 0.0, acc, dec) * dt
            low = prev - np.where(prev > 0.0, dec, acc) * dt
            np.clip(values[:, t], low, high, out=values[:, t])
            prev[:] = values[:, t]
    x0, y0, yaw0 = pose
    yaw = (yaw0 + np.cumsum(wz, axis=1, dtype=np.float64) * dt).astype(vx.dtype)
    heading = np.empty_like(yaw)
    heading[:, 0] = yaw0
    heading[:, 1:] = yaw[:, :-1]
    x = (x0 + np.cumsum(vx * np.cos(heading), axis=1, dtype=np.float64) * dt).astype(vx.dtype)
    y = (y0 + np.cumsum(vx * np.sin(heading), axis=1, dtype=np.float64) * dt).astype(vx.dtype)
    return x, y, yaw


def _constrain_and_integrate_loop(vx, wz, x, y, yaw, x0, y0, yaw0, v0, w0, dt, min_v, max_v,
                                  max_w, v_acc, v_dec, w_acc, w_dec):  # pragma: no cover - numba
    samples, steps = vx.shape
    for s in range(samples):
        pv, pw = v0, w0
        px, py, pyaw = x0, y0, yaw0
        for t in range(steps):
            v = min(max(vx[s, t], min_v), max_v)
            hi = pv + (v_acc if pv >= 0.0 else v_dec) * dt
            lo = pv - (v_dec if pv > 0.0 else v_acc) * dt
            v = min(max(v, lo), hi)
            w = min(max(wz[s, t], -max_w), max_w)
            hi = pw + (w_acc if pw >= 0.0 else w_dec) * dt
            lo = pw - (w_dec if pw > 0.0 else w_acc) * dt
            w = min(max(w, lo), hi)
            # Store, then continue from the stored (float32) values as the reference does.
            vx[s, t] = v
            wz[s, t] = w
            v = vx[s, t]
            w = wz[s, t]
            px += v * np.cos(pyaw) * dt
            py += v * np.sin(pyaw) * dt
            pyaw += w * dt
            x[s, t] = px
            y[s, t] = py
            yaw[s, t] = pyaw
            pv, pw = v, w


_compiled = None


def numba_available() -> bool:
    """Whether the numba fast path is available (the ``numba`` extra is installed)."""
    return _compile() is not None


def _compile():
    global _compiled
    if _compiled is None:
        try:
            import numba
        except ImportError:
            _compiled = False
        else:
            from easynav.common.compiled_kernels import compile_in_child

            _compiled = compile_in_child(
                numba.njit(cache=True, nogil=True)(_constrain_and_integrate_loop),
                "easynav.controllers.mppi.rollout:_compile",
            )
    return _compiled or None


def constrain_and_integrate(
    vx: np.ndarray,
    wz: np.ndarray,
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    dt: float,
    bounds: tuple[float, float, float, float, float, float, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Same contract as :func:`constrain_and_integrate_reference`, in one compiled pass."""
    loop = _compile()
    if loop is None:
        return constrain_and_integrate_reference(vx, wz, pose, velocity, dt, bounds)
    x = np.empty_like(vx)
    y = np.empty_like(vx)
    yaw = np.empty_like(vx)
    # The current velocity rounded to the batch's dtype, as the reference holds it.
    v0, w0 = (float(vx.dtype.type(v)) for v in velocity)
    loop(vx, wz, x, y, yaw, float(pose[0]), float(pose[1]), float(pose[2]), v0, w0, float(dt),
         *(float(b) for b in bounds))
    return x, y, yaw
