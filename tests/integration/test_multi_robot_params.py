"""One params file with per-robot keys (`r1/controller_node:`): each namespace reads its own."""

from __future__ import annotations

import pytest
import yaml

from easynav.common.tf import get_tf_buffer
from easynav.system.testing.system_fixtures import system_params

pytestmark = pytest.mark.ros


def test_each_namespace_reads_its_own_section(tmp_path, runtime_factory):
    document = {}
    for robot, rt_freq in (("r1", 20.0), ("r2", 40.0)):
        params = system_params(
            **{"controller_node.dummy.rt_freq": rt_freq, "system_node.tf_prefix": robot}
        )
        document.update({f"{robot}/{node}": section for node, section in params.items()})
    path = tmp_path / "fleet.yaml"
    path.write_text(yaml.safe_dump(document))
    r1 = runtime_factory(str(path), namespace="r1")
    r2 = runtime_factory(str(path), namespace="r2")
    assert r1.start(), r1.error
    assert r2.start(), r2.error
    assert r1.system_node.controller_node.plugins[0].plugin.rt_freq == 20.0
    assert r2.system_node.controller_node.plugins[0].plugin.rt_freq == 40.0
    assert r1.system_node.controller_node.get_fully_qualified_name() == "/r1/controller_node"
    # tf_prefix gives each robot its own frames.
    assert get_tf_buffer("r1").get_tf_info().robot_frame == "r1/base_link"
    assert get_tf_buffer("r2").get_tf_info().map_frame == "r2/map"
