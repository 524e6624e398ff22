"""Params files are read as ROS 2 reads them (libyaml), so files of the original load unchanged."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from easynav.system.cli.params_file import ParamsFileError, load_params_file, load_ros_yaml
from easynav.system.testing.system_fixtures import system_params

EASYNAV = str(Path(sys.executable).with_name("easynav"))

# As in the original's NavMap workshop files: a tab between a key and its value.
WITH_TABS = (
    "planner_node:\n"
    "  ros__parameters:\n"
    "    planner_types: [dummy]\n"
    "    dummy:\n"
    "      plugin:\teasynav_planner/DummyPlanner\n"
    "      freq:\t5.0\n"
)


def test_a_tab_as_separator_is_accepted_like_libyaml_does():
    document = load_ros_yaml(WITH_TABS)
    assert document["planner_node"]["ros__parameters"]["dummy"]["freq"] == 5.0


def test_a_malformed_file_still_names_the_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("planner_node:\n  ros__parameters:\n    planner_types: [dummy\n")
    with pytest.raises(ParamsFileError, match=r"bad\.yaml: invalid YAML at line"):
        load_params_file(str(bad))


@pytest.mark.ros
def test_easynav_check_loads_a_params_file_with_tabs(tmp_path):
    # The Dummy system's file with tabs in place of the spaces after some keys.
    text = yaml.safe_dump(system_params(), sort_keys=False)
    text = text.replace("rt_freq: ", "rt_freq:\t").replace("freq: ", "freq:\t")
    assert "\t" in text
    path = tmp_path / "tabs.params.yaml"
    path.write_text(text)
    result = subprocess.run(
        [EASYNAV, "check", str(path)], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "configuration OK" in result.stdout
