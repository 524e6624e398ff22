"""MethodBase.geometry_or_deprecated: a plugin's deprecated copy of a robot_geometry field
applies only where robot_geometry does not configure the field (seed: robot_geometry takes
precedence when both are set)."""

from __future__ import annotations

import math

import pytest

from easynav.core.plugins import DictParameters, MethodBase, Param, PluginContext
from easynav.core.robot import RobotGeometry


class Inflating(MethodBase):
    PARAMETERS = (
        Param("inscribed_radius", math.nan, "deprecated: robot_geometry.inscribed_radius", "m",
              ge=0.0, allow_nan=True),
    )

    def inscribed(self) -> float:
        return self.geometry_or_deprecated("inscribed_radius", "inscribed_radius",
                                           also_set_by=("radius",))


def make(values=None, geometry=None):
    geometry = geometry or RobotGeometry()
    plugin = Inflating()
    plugin.initialize(
        PluginContext(parameters=DictParameters({f"inf.{k}": v for k, v in (values or {}).items()}),
                      robot_geometry=lambda: geometry),
        "inf",
    )
    return plugin


@pytest.mark.parametrize(
    ("values", "geometry", "expected", "warning"),
    [
        ({}, RobotGeometry(radius=0.4, inscribed_radius=0.35), 0.35, None),
        ({"inscribed_radius": 0.2}, RobotGeometry(), 0.2,
         "inf.inscribed_radius = 0.2 is deprecated: set system_node.robot_geometry."
         "inscribed_radius instead"),
        ({"inscribed_radius": 0.2},
         RobotGeometry(inscribed_radius=0.3, user_set=frozenset({"inscribed_radius"})), 0.3,
         "inf.inscribed_radius is deprecated and ignored: system_node.robot_geometry."
         "inscribed_radius = 0.3 takes precedence"),
        # The inscribed radius defaults to the radius: setting the radius configures it too.
        ({"inscribed_radius": 0.2},
         RobotGeometry(radius=0.5, inscribed_radius=0.5, user_set=frozenset({"radius"})), 0.5,
         "is deprecated and ignored"),
    ],
)
def test_robot_geometry_takes_precedence_where_it_is_set(values, geometry, expected, warning,
                                                         caplog):
    plugin = make(values, geometry)
    assert plugin.inscribed() == expected
    if warning is None:
        assert "deprecated" not in caplog.text
    else:
        assert warning in caplog.text


def test_the_warning_is_given_once(caplog):
    plugin = make({"inscribed_radius": 0.2})
    for _ in range(3):
        plugin.inscribed()
    assert caplog.text.count("is deprecated") == 1
