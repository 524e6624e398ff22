"""Fixtures of the goal tests; makes the helper modules beside them importable (pytest runs in
importlib mode).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)


@pytest.fixture
def ros_bed(monkeypatch):
    """A ROS test bed (one context, one executor) whose DDS traffic stays inside this process."""
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF")
    from goal_ros_helpers import RosTestbed

    bed = RosTestbed()
    try:
        yield bed
    finally:
        bed.close()
