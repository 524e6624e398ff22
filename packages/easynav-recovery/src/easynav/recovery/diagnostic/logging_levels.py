"""Report levels of mitigations (the numbers of rcl_interfaces/Log and Python logging)."""

from __future__ import annotations

from typing import Any

DEBUG = 10
INFO = 20
WARN = 30
ERROR = 40
FATAL = 50


def log_at(logger: Any, level: int, message: str) -> None:
    """Log ``message`` at ``level`` on an rclpy logger or a Python ``logging.Logger``."""
    if level >= FATAL:
        method = getattr(logger, "fatal", None) or logger.critical
    elif level >= ERROR:
        method = logger.error
    elif level >= WARN:
        method = logger.warning
    elif level >= INFO:
        method = logger.info
    else:
        method = logger.debug
    method(message)
