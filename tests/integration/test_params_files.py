"""Every params file the project ships, and the seed's own file verbatim, pass ``easynav check``.

The seed's file is the block "params/simple.params.yaml of the Kobuki PlayGround" of
``../shared/spec/seed-design.txt`` (relative to the repository root), read straight out of the
spec as the repository's before-stop hook does: a file written for the original must load here
unchanged, its ``package: easynav_playground_kobuki``, ``map_path_file: maps/home.map``
included (easynav-playground ships that map).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[2]
SEED_DESIGN = REPO.parent / "shared" / "spec" / "seed-design.txt"
EASYNAV = str(Path(sys.executable).with_name("easynav"))
#: The line before the block, and the start of the first line after it.
BLOCK_START = "of the Kobuki PlayGround:"
BLOCK_END = "Each node declares"


def seed_block(text: str) -> str:
    """The params block of seed-design.txt (the lines between the two markers)."""
    lines, inside = [], False
    for line in text.splitlines():
        if BLOCK_START in line:
            inside = True
            continue
        if line.startswith(BLOCK_END):
            break
        if inside:
            lines.append(line)
    if not inside:
        raise AssertionError(f"no line with {BLOCK_START!r} in {SEED_DESIGN}")
    return "\n".join(lines) + "\n"


def shipped_params_files() -> list[Path]:
    """params/ of the repository, and every params file of a package (beside it or packaged)."""
    files = set(REPO.glob("params/*.yaml"))
    files |= set(REPO.glob("packages/*/params/*.yaml"))
    files |= set(REPO.glob("packages/*/src/**/params/*.yaml"))
    return sorted(files)


def easynav_check(path: Path, cwd: Path) -> subprocess.CompletedProcess:
    # From another directory: nothing may depend on the working directory being the repo.
    return subprocess.run(
        [EASYNAV, "check", str(path)], capture_output=True, text=True, timeout=120, cwd=cwd
    )


def test_the_seed_params_file_loads_unchanged(tmp_path):
    if not SEED_DESIGN.is_file():
        pytest.skip(f"the seed's spec is not beside the repository ({SEED_DESIGN} is absent)")
    block = seed_block(SEED_DESIGN.read_text())
    assert "easynav_playground_kobuki" in block and "maps/home.map" in block, block
    path = tmp_path / "simple.params.yaml"
    path.write_text(block)
    result = easynav_check(path, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "SimpleMapsManager" in result.stdout, result.stdout


def test_there_are_params_files_to_check():
    names = {p.name for p in shipped_params_files()}
    assert {"simple.params.yaml", "dummy.params.yaml", "playground.params.yaml"} <= names


@pytest.mark.parametrize(
    "path", shipped_params_files(), ids=lambda p: str(p.relative_to(REPO))
)
def test_every_shipped_params_file_passes_the_check(path, tmp_path):
    result = easynav_check(path, tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
