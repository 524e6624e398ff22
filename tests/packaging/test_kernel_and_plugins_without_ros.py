"""The kernel and the plugin distributions without any ROS wheel (issue #13): their wheels,
installed without extras into a fresh environment, bring no ROS distribution, no runtime and no
message package; every plugin class of the catalogue loads there without rclpy, and every
example script runs there.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGES = REPO / "packages"
KERNEL_AND_PLUGINS = [
    "easynav-core", "easynav-common", "easynav-maps", "easynav-localizers", "easynav-planners",
    "easynav-controllers", "easynav-recovery", "easynav-faulty",
]
GROUPS = [
    "easynav.controllers", "easynav.localizers", "easynav.planners", "easynav.maps_managers",
    "easynav.recovery_managers",
]

pytestmark = [
    pytest.mark.slow,
    # Eight wheels built and installed with numpy, opencv and PyYAML (from pip's cache when it
    # has them), then eight examples: a few minutes on a loaded machine.
    pytest.mark.timeout(900),
]


def _examples_module():
    """test_examples.py (beside this file): its examples, expectations and environment."""
    spec = importlib.util.spec_from_file_location(
        "easynav_test_examples", Path(__file__).with_name("test_examples.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


EXAMPLES = _examples_module()

LOAD_PLUGINS = textwrap.dedent(f"""
    import json, sys
    from importlib.metadata import entry_points
    import easynav.core
    loaded, failed = [], {{}}
    for group in {GROUPS!r}:
        for ep in entry_points(group=group):
            try:
                ep.load()
                loaded.append(group + ":" + ep.name)
            except Exception as exc:
                failed[group + ":" + ep.name] = f"{{type(exc).__name__}}: {{exc}}"
    ros = sorted(m for m in sys.modules
                 if m.split(".")[0] == "rclpy" or m.split(".")[0].endswith("_msgs")
                 or m == "easynav.system" or m.startswith("easynav.system."))
    print(json.dumps({{"loaded": loaded, "failed": failed, "ros_modules": ros}}))
""")


def declared_plugins() -> list[str]:
    """``group:name`` of every entry point the kernel and the plugin distributions declare in
    the plugin groups."""
    declared = []
    for name in KERNEL_AND_PLUGINS:
        project = EXAMPLES.tomllib.loads((PACKAGES / name / "pyproject.toml").read_text())
        for group, points in project["project"].get("entry-points", {}).items():
            if group in GROUPS:
                declared += [f"{group}:{point}" for point in points]
    return sorted(declared)


def run(cmd: list[str], timeout: float = 600, **kwargs) -> subprocess.CompletedProcess:
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                            env=EXAMPLES.example_environment(), **kwargs)
    assert result.returncode == 0, f"{' '.join(cmd)}\n{result.stdout}\n{result.stderr}"
    return result


def test_kernel_and_plugin_wheels_install_and_run_without_ros(tmp_path):
    wheels = tmp_path / "wheels"
    for name in KERNEL_AND_PLUGINS:
        # Pure-Python hatchling wheels, built with the development environment's build tools.
        run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps",
             "--no-build-isolation", str(PACKAGES / name), "-w", str(wheels)])
    built = sorted(wheels.glob("*.whl"))
    assert len(built) == len(KERNEL_AND_PLUGINS), built

    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", str(venv)])
    vpy = str(venv / "bin" / "python")
    # The built wheels by path (so they, not a same-named distribution of an index, are the
    # ones installed) and as the place to find siblings; no extras.
    run([vpy, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
         "--find-links", str(wheels), *map(str, built)], timeout=900)

    listed = run([vpy, "-m", "pip", "list", "--format=freeze",
                  "--disable-pip-version-check"]).stdout
    names = sorted(line.split("==")[0].lower() for line in listed.splitlines() if "==" in line)
    assert not [n for n in names if n.startswith("ros-")], names
    assert "easynav-system" not in names and "easynav-interfaces" not in names, names
    assert [n for n in names if n.startswith("easynav")] == sorted(KERNEL_AND_PLUGINS), names

    # From a folder outside the repository: only the installed wheels are importable.
    report = json.loads(run([vpy, "-c", LOAD_PLUGINS], cwd=tmp_path).stdout)
    assert not report["failed"], report["failed"]
    assert not report["ros_modules"], report["ros_modules"]
    assert sorted(report["loaded"]) == declared_plugins()

    failures = []
    for script in EXAMPLES.EXAMPLES:
        workdir = tmp_path / "run" / script.stem
        workdir.mkdir(parents=True)
        result = subprocess.run([vpy, str(script)], cwd=workdir, capture_output=True, text=True,
                                timeout=120, env=EXAMPLES.example_environment())
        if result.returncode != 0:
            failures.append(f"{EXAMPLES.key(script)} exited {result.returncode}:\n"
                            f"{result.stdout}\n{result.stderr[-3000:]}")
            continue
        try:
            EXAMPLES.check_output(script, result.stdout)
        except AssertionError as exc:
            failures.append(str(exc))
    assert not failures, "\n\n".join(failures)
