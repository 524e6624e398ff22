"""The process-wide TF buffers: one per robot namespace (the original's RTTFBuffer singleton)."""

from __future__ import annotations

import threading

from easynav.core.tf.tf_buffer import TFBuffer

_lock = threading.Lock()
_buffers: dict[str, TFBuffer] = {}


def _normalize(namespace: str) -> str:
    return "/" + namespace.strip("/") if namespace.strip("/") else ""


def get_tf_buffer(namespace: str = "") -> TFBuffer:
    """The buffer shared by everything in this process for ``namespace`` (created on first use).

    One EasyNav process usually serves one robot and uses ``""``; tests and tools that host
    several robots in one process pass the robot's namespace (``"r1"`` and ``"/r1"`` are the
    same). Thread contract: safe from any thread.
    """
    key = _normalize(namespace)
    with _lock:
        buffer = _buffers.get(key)
        if buffer is None:
            buffer = TFBuffer()
            _buffers[key] = buffer
        return buffer


def reset_tf_buffers() -> None:
    """Forget every process-wide buffer (for tests; a running system must not call it)."""
    with _lock:
        _buffers.clear()
