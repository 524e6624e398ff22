"""NoiseGenerator: the next cycle's sampling noise, drawn while the controller waits."""

from __future__ import annotations

import math
from concurrent.futures import Future, ThreadPoolExecutor

import numpy as np


class NoiseGenerator:
    """Standard-normal noise for a batch, ``(2, samples, steps)`` float32, drawn ahead.

    Drawing 2 × 2000 × 56 normals takes about as long as the rest of an MPPI cycle, so (as Nav2
    does) the noise for the next cycle is drawn in a worker thread right after the current one
    is handed out: it runs while the RT thread waits for its next period (numpy releases the GIL
    while it fills the array). :meth:`take` waits only if that draw has not finished.

    ``constant_ratio`` of the variance is one draw per sample held along its steps (see the
    optimiser's ``constant_noise_ratio``); each step keeps unit variance.

    Thread contract: :meth:`take` and :meth:`close` from one thread (the RT thread); the worker
    touches only the buffer it is filling. Exceptions: none (a worker's exception is re-raised
    by :meth:`take`).
    """

    def __init__(self, samples: int, steps: int, seed: int | None, background: bool = True):
        self.shape = (2, samples, steps)
        self._rng = np.random.default_rng(seed)
        self._executor = (
            ThreadPoolExecutor(max_workers=1, thread_name_prefix="mppi_noise")
            if background else None
        )
        self._pending: Future | None = None
        self._ratio = 0.0

    def _draw(self, ratio: float) -> np.ndarray:
        noise = self._rng.standard_normal(self.shape, dtype=np.float32)
        if ratio > 0.0:
            constant = self._rng.standard_normal(self.shape[:2] + (1,), dtype=np.float32)
            noise *= np.float32(math.sqrt(1.0 - ratio))
            noise += np.float32(math.sqrt(ratio)) * constant
        return noise

    def take(self, constant_ratio: float) -> np.ndarray:
        """Noise for this cycle (a fresh array the caller owns); starts the next draw."""
        if self._pending is not None and self._ratio == constant_ratio:
            noise = self._pending.result()
        else:
            if self._pending is not None:
                self._pending.result()  # the worker owns the generator until it finishes
            noise = self._draw(constant_ratio)
        self._ratio = constant_ratio
        self._pending = (
            self._executor.submit(self._draw, constant_ratio) if self._executor else None
        )
        return noise

    def close(self) -> None:
        """Stop the worker (waits for a draw in progress)."""
        if self._executor is not None:
            self._executor.shutdown(wait=True)
            self._executor = None
        self._pending = None
