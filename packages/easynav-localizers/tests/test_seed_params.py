"""The original EasyNav's example simple.params.yaml (the Kobuki playground's): this package's
section loads its plugin unchanged."""

from __future__ import annotations

import pytest

from easynav.core.plugins.plugin_kinds import LOCALIZER
from easynav.system.testing.params_section_plugin import plugin_from_params_section

pytestmark = pytest.mark.ros

# Verbatim from the original EasyNav's documentation ("Core Design and Architecture": the
# Kobuki playground's params/simple.params.yaml, simplified).
SEED = """
localizer_node:
  ros__parameters:
    use_sim_time: true
    localizer_types: [simple]
    simple:
      rt_freq: 50.0
      freq: 5.0
      reseed_freq: 1.0
      plugin: easynav_simple_localizer/AMCLLocalizer
      num_particles: 100
      noise_translation: 0.05
      noise_rotation: 0.1
      noise_translation_to_rotation: 0.1
      initial_pose:
        x: 0.0
        y: 0.0
        yaw: 0.0
        std_dev_xy: 0.1
        std_dev_yaw: 0.01
"""


def test_seed_section_configures_the_plugin_through_ros_parameters(tmp_path):
    pytest.importorskip("rclpy")
    seed = plugin_from_params_section(SEED, "localizer_node", LOCALIZER, tmp_path)
    with seed as (plugin, section):
        assert section["localizer_types"] == ["simple"]
        assert (plugin.rt_freq, plugin.freq) == (50.0, 5.0)
        assert plugin.reseed_period == 1.0
        assert len(plugin.filter) == 100
        assert plugin.noise == (0.05, 0.1, 0.1)
        assert plugin.filter.poses[:, :2].std(axis=0).max() < 0.2  # std_dev_xy 0.1
        assert plugin.min_noise_yaw == 0.05
