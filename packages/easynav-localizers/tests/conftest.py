"""The shared `ros` fixture (easynav.system.testing) with a node named as this plugin's host."""

from __future__ import annotations

import pytest


@pytest.fixture
def ros(ros):
    """``ros.node`` is a node named ``localizer_node``, spun by ``ros.spin_until``."""
    ros.node = ros.create_node("localizer_node")
    return ros
