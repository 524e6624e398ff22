"""Make the helper modules beside these tests importable (pytest runs in importlib mode)."""

from __future__ import annotations

import sys
from pathlib import Path

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)


import pytest  # noqa: E402


@pytest.fixture
def ros_local(monkeypatch):
    """A rclpy context whose DDS traffic stays in this process (discovery range OFF)."""
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    from easynav.core.testing.ros_fixtures import RosTestContext

    ctx = RosTestContext()
    try:
        yield ctx
    finally:
        ctx.shutdown()
