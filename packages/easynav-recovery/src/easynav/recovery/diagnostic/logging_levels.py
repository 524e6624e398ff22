"""Report levels of mitigations (the numbers of rcl_interfaces/Log and Python logging)."""

from __future__ import annotations

from typing import Any

DEBUG = 10
INFO = 20
WARN = 30
ERROR = 40
FATAL = 50


def log_at(logger: Any, level: int, message: str) -> None:
    """Log ``message`` at ``level`` on an rclpy logger or a Python ``logging.Logger``.

    One call per severity on its own line: rclpy raises ValueError when one call site logs at
    different severities ("Logger severity cannot be changed between calls").
    """
    if level >= FATAL:
        if hasattr(logger, "fatal"):
            logger.fatal(message)
        else:
            logger.critical(message)
    elif level >= ERROR:
        logger.error(message)
    elif level >= WARN:
        logger.warning(message)
    elif level >= INFO:
        logger.info(message)
    else:
        logger.debug(message)
