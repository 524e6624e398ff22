"""An empty list in a params file (``filters: []``): rclpy reads it as NOT_SET; NodeParameters
declares it as the empty list the user wrote, typed like the declaration's default."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.ros


def test_empty_lists_in_a_params_file(tmp_path):
    rclpy = pytest.importorskip("rclpy")
    from easynav.system.node_parameters import NodeParameters

    path = tmp_path / "p.yaml"
    path.write_text(
        "n:\n  ros__parameters:\n    a.filters: []\n    a.weights: []\n    a.names: [x]\n"
    )
    context = rclpy.Context()
    rclpy.init(args=["--ros-args", "--params-file", str(path)], context=context)
    try:
        node = rclpy.create_node("n", context=context)
        params = NodeParameters(node)
        assert params.declare("a.filters", []) == []
        assert params.declare("a.weights", [1.0, 2.0]) == []  # the user's [] wins
        assert params.declare("a.names", []) == ["x"]
        assert params.declare("a.other", []) == []  # not in the file: the default
        assert params.declare("a.filters", []) == []  # declared already: the same answer
        assert params.declare("a.weights", [1.0, 2.0]) == []
        assert params.is_set("a.filters") and not params.is_set("a.other")
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
