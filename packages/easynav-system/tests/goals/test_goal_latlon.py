"""``easynav goal --latlon``: argument checks and the conversion to the map frame."""

from __future__ import annotations

import io

import pytest

from easynav.system.goals.goal_command import goal_command, latlon_to_map


@pytest.mark.parametrize(
    ("argv", "message"),
    [(["40.28", "-3.82", "--latlon"], "--latlon needs --origin"),
     (["95.0", "-3.82", "--latlon", "--origin", "40.28", "-3.82"], "latitude must be within"),
     (["40.28", "-3.82", "--latlon", "--origin", "40.28", "-190"], "--origin longitude"),
     (["1", "2", "--origin", "40.28", "-3.82"], "--origin is only for --latlon"),
     (["40.28", "-3.82", "--latlon", "--origin", "40.28", "-3.82", "--frame", "odom"],
      "map frame")],
)
def test_bad_latlon_arguments_return_two(argv, message):
    err = io.StringIO()
    assert goal_command(argv, out=io.StringIO(), err=err) == 2
    assert message in err.getvalue()


def test_latlon_becomes_map_coordinates():
    pytest.importorskip("pyproj")
    pytest.importorskip("easynav.localizers.fusion.utm_projection")
    # The campus world's first waypoint: (30, 3) m from the origin.
    x, y = latlon_to_map(40.28352263, -3.82037285, (40.2834931, -3.8207254))
    assert (x, y) == pytest.approx((30.0, 3.0), abs=0.01)
    assert latlon_to_map(40.2834931, -3.8207254, (40.2834931, -3.8207254)) == pytest.approx(
        (0.0, 0.0), abs=1e-6)
