"""Savitzky–Golay smoothing of an MPPI control sequence (Nav2 smooths its optimal sequence)."""

from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=8)
def savgol_coefficients(window: int = 9, order: int = 2) -> np.ndarray:
    """Weights that give the least-squares polynomial of ``order`` at the centre of ``window``.

    Row 0 of the pseudo-inverse of the Vandermonde matrix over offsets ``-h..h`` (h =
    window // 2): the fitted polynomial's value at offset 0. ``window`` odd, ``order < window``.
    """
    if window % 2 != 1 or window < 3:
        raise ValueError(f"Savitzky-Golay window = {window} must be odd and >= 3")
    if not 0 <= order < window:
        raise ValueError(f"Savitzky-Golay order = {order} must be in [0, window)")
    half = window // 2
    offsets = np.arange(-half, half + 1, dtype=float)
    vandermonde = offsets[:, None] ** np.arange(order + 1)[None, :]
    coefficients = np.linalg.pinv(vandermonde)[0]
    coefficients.setflags(write=False)
    return coefficients


def smooth_sequence(
    sequence: np.ndarray, history: np.ndarray, window: int = 9, order: int = 2
) -> np.ndarray:
    """``sequence`` (T×C) smoothed along time.

    The past is the ``history`` of applied commands (H×C, oldest first; fewer than window // 2
    rows are padded with the oldest, none with the sequence's first), the future is padded with
    the sequence's last row, so the first command stays continuous with what the robot did.
    """
    half = window // 2
    steps = len(sequence)
    if steps == 0:
        return sequence.copy()
    past = history[-half:] if len(history) else sequence[:1]
    if len(past) < half:
        past = np.vstack((np.repeat(past[:1], half - len(past), axis=0), past))
    future = np.repeat(sequence[-1:], half, axis=0)
    padded = np.vstack((past, sequence, future)).astype(np.float64)
    coefficients = savgol_coefficients(window, order)
    # Correlation with the (symmetric) weights: out[t] = Σ_k c[k]·padded[t + k].
    out = np.zeros((steps, sequence.shape[1]))
    for k, c in enumerate(coefficients):
        out += c * padded[k : k + steps]
    return out.astype(sequence.dtype)
