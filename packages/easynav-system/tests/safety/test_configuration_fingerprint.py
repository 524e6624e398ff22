"""ConfigurationFingerprint: the text, the SHA-256, the saved file, the topic and the log."""

import hashlib
import os
import random
import shutil
import subprocess
from pathlib import Path

import pytest

from easynav.system.safety import ConfigurationFingerprint, format_value, ros_log_dir

PARAMETERS = [
    ("controller_node", "cmd_timeout", "double", 0.5),
    ("controller_node", "controller_types", "string_array", ["ctrl"]),
    ("controller_node", "ctrl.plugin", "string", "easynav_simple_controller/SimpleController"),
    ("controller_node", "ctrl.rt_freq", "double", 30.0),
    ("system_node", "safety.mode", "bool", False),
    ("system_node", "safety.rt_monitor.max_late_cycles", "integer", 10),
    ("system_node", "weights", "double_array", [1.0, 2.5]),
    ("system_node", "flags", "bool_array", [True, False]),
    ("system_node", "counts", "integer_array", [1, -2]),
    ("system_node", "raw", "byte_array", b"\x01\xff"),
]


def changed(index, value):
    params = list(PARAMETERS)
    node, name, type_name, _ = params[index]
    params[index] = (node, name, type_name, value)
    return ConfigurationFingerprint(params)


def test_text_is_sorted_typed_one_line_per_parameter_as_the_spec_shows():
    text = ConfigurationFingerprint(PARAMETERS).text
    assert text.splitlines()[:3] == [
        "controller_node/cmd_timeout (double) = 0.5",
        'controller_node/controller_types (string_array) = ["ctrl"]',
        'controller_node/ctrl.plugin (string) = "easynav_simple_controller/SimpleController"',
    ]
    assert "system_node/safety.mode (bool) = false\n" in text
    assert "system_node/weights (double_array) = [1.0, 2.5]\n" in text
    assert "system_node/flags (bool_array) = [true, false]\n" in text
    assert "system_node/counts (integer_array) = [1, -2]\n" in text
    assert "system_node/raw (byte_array) = [1, 255]\n" in text
    assert text.endswith("\n") and len(text.splitlines()) == len(PARAMETERS)
    assert text.splitlines() == sorted(text.splitlines())


def test_hash_is_sha256_of_the_text():
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    assert fingerprint.hash == hashlib.sha256(fingerprint.text.encode()).hexdigest()
    assert len(fingerprint.hash) == 64


def test_same_parameters_in_another_order_give_the_same_hash():
    shuffled = list(PARAMETERS)
    random.Random(4).shuffle(shuffled)
    assert ConfigurationFingerprint(shuffled).hash == ConfigurationFingerprint(PARAMETERS).hash


def test_one_changed_value_or_default_changes_the_hash():
    base = ConfigurationFingerprint(PARAMETERS).hash
    assert changed(0, 0.51).hash != base
    assert changed(4, True).hash != base
    # A new default shows up as a different effective value, or as a new parameter.
    extra = ConfigurationFingerprint([*PARAMETERS, ("system_node", "new", "double", 1.0)])
    assert extra.hash != base


def test_a_newline_in_a_string_cannot_fake_another_line():
    honest = ConfigurationFingerprint([("n", "a", "string", "x"), ("n", "b", "string", "y")])
    forged = ConfigurationFingerprint([("n", "a", "string", 'x"\nn/b (string) = "y')])
    assert forged.hash != honest.hash
    assert len(forged.text.splitlines()) == 1
    for separator in ["\r", "\x85", "\u2028", "\u2029", "\x0b", "\x0c", "\x1c"]:
        text = ConfigurationFingerprint([("n", "a", "string", f"x{separator}y")]).text
        assert len(text.splitlines()) == 1, repr(separator)


def test_close_doubles_are_written_exactly():
    a = ConfigurationFingerprint([("n", "x", "double", 0.1 + 0.2)])
    b = ConfigurationFingerprint([("n", "x", "double", 0.3)])
    assert a.hash != b.hash
    assert a.text == "n/x (double) = 0.30000000000000004\n"
    assert float(format_value("double", 1e-300 * 3)) == 1e-300 * 3


def test_types_are_distinguished():
    texts = {
        ConfigurationFingerprint([("n", "x", type_name, value)]).hash
        for type_name, value in [("integer", 1), ("double", 1.0), ("string", "1")]
    }
    assert len(texts) == 3


@pytest.mark.parametrize(
    ("type_name", "value"),
    [
        ("double", "0.5"),
        ("integer", 1.5),
        ("bool", 1),
        ("string", 3),
        ("integer", True),
        ("string_array", "abc"),
        ("byte_array", [256]),
    ],
)
def test_a_value_of_the_wrong_type_is_an_error_naming_the_parameter(type_name, value):
    with pytest.raises(TypeError, match="system_node/p"):
        ConfigurationFingerprint([("system_node", "p", type_name, value)])


def test_unknown_type_duplicates_and_line_breaks_in_names_are_errors():
    with pytest.raises(ValueError, match="unknown parameter type 'float'"):
        ConfigurationFingerprint([("n", "p", "float", 1.0)])
    with pytest.raises(ValueError, match="n/p given twice"):
        ConfigurationFingerprint([("n", "p", "double", 1.0), ("n", "p", "double", 2.0)])
    with pytest.raises(ValueError, match="line break"):
        ConfigurationFingerprint([("n", "p\nq", "double", 1.0)])


def test_not_set_parameters_are_written_null():
    assert ConfigurationFingerprint([("n", "p", "not_set", None)]).text == "n/p (not_set) = null\n"


def test_saved_file_sha256sum_equals_the_hash_in_its_name(tmp_path):
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    path, warning = fingerprint.save(tmp_path / "log", "")
    assert warning is None
    assert path == tmp_path / "log" / f"easynav_configuration_{fingerprint.hash}.txt"
    assert hashlib.sha256(path.read_bytes()).hexdigest() == fingerprint.hash
    if shutil.which("sha256sum"):
        output = subprocess.run(["sha256sum", str(path)], capture_output=True, text=True)
        assert output.stdout.split()[0] == fingerprint.hash


@pytest.mark.parametrize(
    ("namespace", "middle"), [("/robot1", "robot1_"), ("/a/b", "a_b_"), ("/", ""), ("r2", "r2_")]
)
def test_file_name_carries_the_namespace(tmp_path, namespace, middle):
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    path, _ = fingerprint.save(tmp_path, namespace)
    assert path.name == f"easynav_configuration_{middle}{fingerprint.hash}.txt"


def test_an_existing_file_is_not_rewritten(tmp_path):
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    path, _ = fingerprint.save(tmp_path)
    os.utime(path, (1_000_000, 1_000_000))
    assert fingerprint.save(tmp_path) == (path, None)
    assert path.stat().st_mtime == 1_000_000
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


def test_saving_never_raises_and_returns_a_warning(tmp_path):
    blocker = tmp_path / "not_a_directory"
    blocker.write_text("x")
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    path, warning = fingerprint.save(blocker / "log")
    assert path is None
    assert warning.startswith(f"could not save the configuration to {blocker / 'log'}")
    assert "(not saved: could not save" in fingerprint.log_lines({})[1]


def test_ros_log_dir_resolution(monkeypatch, tmp_path):
    monkeypatch.setenv("ROS_LOG_DIR", str(tmp_path / "a"))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "b"))
    assert ros_log_dir() == tmp_path / "a"
    monkeypatch.setenv("ROS_LOG_DIR", "")
    assert ros_log_dir() == tmp_path / "b" / "log"
    monkeypatch.delenv("ROS_LOG_DIR")
    monkeypatch.delenv("ROS_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert ros_log_dir() == tmp_path / "home" / ".ros" / "log"
    monkeypatch.setenv("ROS_LOG_DIR", "~/logs")
    assert ros_log_dir() == tmp_path / "home" / "logs"


def test_topic_text_starts_with_the_hash():
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    lines = fingerprint.topic_text().split("\n", 1)
    assert lines[0] == f"# SHA-256: {fingerprint.hash}"
    assert lines[1] == fingerprint.text


def test_log_lines_as_the_spec_shows(tmp_path):
    fingerprint = ConfigurationFingerprint(PARAMETERS)
    path, _ = fingerprint.save(tmp_path)
    lines = fingerprint.log_lines(
        {
            "controller_node": [("ctrl", "easynav_simple_controller/SimpleController")],
            "maps_manager_node": [("a", "x/A"), ("b", "x/B")],
        }
    )
    assert lines == [
        f"Configuration SHA-256: {fingerprint.hash}",
        f"  ({Path(path)}). Plugins:",
        "  controller_node: ctrl [easynav_simple_controller/SimpleController]",
        "  maps_manager_node: a [x/A], b [x/B]",
    ]
