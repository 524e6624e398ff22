"""Every plugin distribution's examples (packages/*/examples/*.py) run without ROS and print what
they promise; they import nothing but the kernel, their own distribution and its declared
dependencies (never the runtime, rclpy or a message package).

The slow test_kernel_and_plugins_without_ros.py runs the same scripts, with the same
expectations (``EXPECTED``), in a fresh environment without any ROS wheel.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from packaging.requirements import Requirement

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

REPO = Path(__file__).resolve().parents[2]
PACKAGES = REPO / "packages"
EXAMPLES = sorted(PACKAGES.glob("*/examples/*.py"))

#: For each example (package folder / script): patterns its output must hold (re.MULTILINE).
EXPECTED: dict[str, list[str]] = {
    "easynav-controllers/controllers_on_path.py": [
        r"^SimpleController +arrived after .* final distance 0\.\d+ m",
        r"^RegulatedPurePursuitController +arrived after .* final distance 0\.\d+ m",
        r"^MPPIController +arrived after .* final distance 0\.\d+ m",
    ],
    "easynav-controllers/follow_path.py": [r"^arrived after [\d.]+ s: 0\.\d+ m from the end"],
    "easynav-faulty/inject_faults.py": [
        r"^update 1: robot_pose \(1\.00, 2\.00\) +path of 21 poses, finite +cmd_vel vx 0\.2 ",
        r"^update 5: robot_pose \(2\.00, 2\.00\) +path of \d+ poses, NOT FINITE +cmd_vel vx 1000 ",
    ],
    "easynav-localizers/amcl_on_house.py": [r"^final error 0\.[01]\d+ m, "],
    "easynav-maps/costmap_example.py": [
        r"^map \(after the filters\): \d+ lethal, \d+ inscribed",
        r"^cost where the laser saw the box \(3\.05, 4\.5\): 254 ",
        r"^speed limit at \(1, 1\): 0\.23 of robot_limits",
    ],
    "easynav-maps/simple_map_example.py": [r"^downsampled SimpleMap", r"^saved and reloaded "],
    "easynav-planners/plan_in_house.py": [r"^goal \(8\.5, 6\.0\): 1\d\.\d+ m smoothed"],
    "easynav-planners/plan_path.py": [
        r"^SimplePlanner: path of 1\d\.\d+ m, \d+ poses",
        r"^CostmapPlanner: path of 1\d\.\d+ m, \d+ poses",
        r"^  waypoints: \(0\.\d+, 0\.\d+\) .*\(8\.50, 6\.00\)$",
    ],
    "easynav-recovery/simple_recovery.py": [
        r"recovery OVERRIDE drives \(vx \+0\.00",
        r"recovery TAKEOVER drives \(vx -0\.10 .*mitigation back_up",
        r"^   commanded backing up for 1\.\d+ s",
    ],
}

#: Distributions whose examples these are, and the import package of each sibling.
MODULE_OF = {
    "easynav-core": "easynav.core",
    "easynav-common": "easynav.common",
    "easynav-maps": "easynav.maps",
    "easynav-localizers": "easynav.localizers",
    "easynav-planners": "easynav.planners",
    "easynav-controllers": "easynav.controllers",
    "easynav-recovery": "easynav.recovery",
    "easynav-faulty": "easynav.faulty",
}


def key(script: Path) -> str:
    return f"{script.parent.parent.name}/{script.name}"


def example_environment() -> dict[str, str]:
    """This environment without what the ROS wheels' start-up set for the development venv."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE", "PYTHONPATH")}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def check_output(script: Path, stdout: str) -> None:
    for pattern in EXPECTED[key(script)]:
        assert re.search(pattern, stdout, re.MULTILINE), (
            f"{key(script)}: no line matches {pattern!r} in:\n{stdout}")


def allowed_modules(distribution: str) -> set[str]:
    """easynav.core, the distribution's own package and its declared sibling dependencies."""
    project = tomllib.loads((PACKAGES / distribution / "pyproject.toml").read_text())["project"]
    names = {distribution, "easynav-core"}
    names |= {Requirement(r).name for r in project.get("dependencies", [])}
    return {MODULE_OF[name] for name in names if name in MODULE_OF}


def imported_modules(script: Path) -> set[str]:
    modules = set()
    for node in ast.walk(ast.parse(script.read_text(), str(script))):
        if isinstance(node, ast.Import):
            modules |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            modules.add(node.module)
    return modules


def test_every_example_has_expectations():
    assert {key(s) for s in EXAMPLES} == set(EXPECTED)
    for distribution in ("maps", "localizers", "planners", "controllers", "recovery"):
        assert any(s.parent.parent.name == f"easynav-{distribution}" for s in EXAMPLES)


@pytest.mark.parametrize("script", EXAMPLES, ids=key)
def test_example_imports_only_the_kernel_and_its_distribution(script):
    allowed = allowed_modules(script.parent.parent.name)
    for module in imported_modules(script):
        root = module.split(".")[0]
        assert root != "rclpy" and not root.endswith("_msgs"), f"{key(script)}: {module}"
        if root == "easynav":
            assert any(module == a or module.startswith(a + ".") for a in allowed), (
                f"{key(script)} imports {module}; allowed: {sorted(allowed)}")


@pytest.mark.parametrize("script", EXAMPLES, ids=key)
def test_example_runs_and_prints_its_result(script, tmp_path):
    result = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
        timeout=60, env=example_environment(),
    )
    assert result.returncode == 0, f"{key(script)}:\n{result.stdout}\n{result.stderr}"
    check_output(script, result.stdout)
    assert not list(tmp_path.iterdir()), "an example left files in its working directory"
