"""The process-wide TF buffers: one per robot namespace (the original's RTTFBuffer singleton)."""

from __future__ import annotations

import threading

from easynav.common.tf.tf_buffer import TFBuffer

_lock = threading.Lock()
_buffers: dict[str, TFBuffer] = {}
_default_namespace: str | None = None


def _normalize(namespace: str) -> str:
    # "r1", "/r1" and "/r1/" name the same robot; "" and "/" the root namespace.
    return namespace.strip("/")


def _default_key() -> str:
    if _default_namespace is not None:
        return _default_namespace
    # One EasyNav process serves one robot: when exactly one buffer was given a TFInfo (by
    # system_node, under its namespace), that is the robot's buffer, namespaced or not.
    configured = [key for key, buffer in _buffers.items() if buffer.has_tf_info]
    return configured[0] if len(configured) == 1 else ""


def get_tf_buffer(namespace: str | None = None) -> TFBuffer:
    """The buffer shared by everything in this process for ``namespace`` (created on first use).

    ``namespace`` None (what plugins use) is this process's robot: the namespace set with
    :func:`set_default_tf_namespace`, else the only buffer that was given a TFInfo, else the
    root namespace ``""``. Hosts that know their namespace (system_node, the TF listener) pass it
    (``"r1"`` and ``"/r1"`` are the same). Thread contract: safe from any thread.
    """
    with _lock:
        key = _default_key() if namespace is None else _normalize(namespace)
        buffer = _buffers.get(key)
        if buffer is None:
            buffer = TFBuffer()
            _buffers[key] = buffer
        return buffer


def set_default_tf_namespace(namespace: str | None) -> None:
    """Make ``get_tf_buffer()`` return the buffer of ``namespace`` (None: automatic choice)."""
    global _default_namespace
    with _lock:
        _default_namespace = None if namespace is None else _normalize(namespace)


def reset_tf_buffers() -> None:
    """Forget every process-wide buffer and the default (tests only; never in a running system)."""
    global _default_namespace
    with _lock:
        _buffers.clear()
        _default_namespace = None
