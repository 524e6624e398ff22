"""``easynav plugins --describe`` and the unknown-key report of ``easynav check``."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from easynav.system.cli.main import main
from easynav.system.cli.params_file import load_params_file
from easynav.system.cli.unknown_keys import unknown_keys

REPO = Path(__file__).resolve().parents[4]


def test_describe_lists_parameters_topics_and_navstate_keys(capsys):
    assert main(["plugins", "--describe", "easynav_controller/DummyController"]) == 0
    out = capsys.readouterr().out
    assert "cycle_time_rt" in out and "float" in out and ">= 0" in out
    assert "NavState keys read:" in out and "Topics:" in out


def test_describe_an_unknown_name_suggests_close_ones(capsys):
    assert main(["plugins", "--describe", "easynav_controller/DumyController"]) == 2
    assert "Did you mean easynav_controller/DummyController" in capsys.readouterr().err


def test_describe_the_simple_controller(capsys):
    pytest.importorskip("easynav.controllers")
    assert main(["plugins", "--describe", "easynav_simple_controller/SimpleController"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.strip().startswith("look_ahead_dist"))
    # The original SimpleController's default is 1.0; the Kobuki playground's params file
    # (simple.params.yaml) sets 0.2.
    assert row.split()[1:4] == ["float", "1.0", "m"]
    assert any(line.strip().startswith("k_rot ") for line in out.splitlines())
    assert "cmd_vel" in out and "path" in out


def _typo_copy(tmp_path: Path) -> Path:
    copy = tmp_path / "simple.params.yaml"
    shutil.copy(REPO / "params" / "simple.params.yaml", copy)
    text = copy.read_text()
    assert "look_ahead_dist" in text
    copy.write_text(text.replace("look_ahead_dist", "look_ahed_dist"))
    return copy


def test_a_misspelt_key_is_named_with_the_right_one(tmp_path):
    pytest.importorskip("easynav.controllers")
    found = unknown_keys(load_params_file(str(_typo_copy(tmp_path))))
    assert [item.message() for item in found] == [
        "controller_node: simple.look_ahed_dist: unknown parameter, did you mean look_ahead_dist?"
    ]


def test_strict_check_fails_before_configuring(tmp_path, capsys):
    pytest.importorskip("easynav.controllers")
    assert main(["check", "--strict", str(_typo_copy(tmp_path))]) == 2
    err = capsys.readouterr().err
    assert "error:" in err and "simple.look_ahed_dist: unknown parameter, did you mean " \
        "look_ahead_dist?" in err


@pytest.mark.parametrize(
    "path",
    sorted(str(p.relative_to(REPO)) for p in (REPO / "params").glob("*.yaml"))
    + sorted(
        str(p.relative_to(REPO)) for p in (REPO / "packages").glob("*/**/params/*.params.yaml")
        if ".venv" not in p.parts
    ),
)
def test_the_shipped_params_files_have_no_unknown_key(path):
    assert [u.message() for u in unknown_keys(load_params_file(str(REPO / path)))] == []


def test_the_seed_blocks_have_no_unknown_key():
    import yaml

    seed = Path("/work/shared/spec/seed-design.txt")
    if not seed.is_file():
        pytest.skip("seed-design.txt not available")
    text = seed.read_text()
    start = text.index(
        "controller_node:\n  ros__parameters:\n    use_sim_time: true\n    robot_limits"
    )
    end = text.index("Each node declares one or more plugin types")
    assert unknown_keys(yaml.safe_load(text[start:end])) == []


def test_node_level_groups_are_checked():
    document = {
        "controller_node": {"ros__parameters": {"robot_limits": {"max_linear_vell": 0.3}}},
        "system_node": {"ros__parameters": {"robot_geometry": {"radios": 0.3}}},
    }
    assert [u.message() for u in unknown_keys(document)] == [
        "controller_node: robot_limits.max_linear_vell: unknown parameter, did you mean "
        "max_linear_vel?",
        "system_node: robot_geometry.radios: unknown parameter, did you mean radius?",
    ]


def test_recovery_sub_plugin_keys_are_checked():
    pytest.importorskip("easynav.recovery")
    document = {"recovery_node": {"ros__parameters": {"recovery_manager": {
        "plugin": "easynav_diagnostic_recovery/DiagnosticRecoveryManager",
        "evaluator_types": ["stuck"],
        "stuck": {
            "plugin": "easynav_controller_stuck_evaluator/ControllerStuckEvaluator",
            "stuck_time_treshold": 2.0,
        },
        "mitigation_types": ["advance"],
        "advance": {"plugin": "easynav_advance_recovery/AdvanceRecovery", "priority": 10},
    }}}}
    assert [u.message() for u in unknown_keys(document)] == [
        "recovery_node: recovery_manager.stuck.stuck_time_treshold: unknown parameter, did you "
        "mean stuck_time_threshold?"
    ]
