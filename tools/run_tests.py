"""The whole test suite: ruff, the release consistency check, pytest over every package and
tests/, then the kernel and a plugin distribution installed alone on the oldest and the newest
supported Python.

Usage: .venv/bin/python tools/run_tests.py [--fast] [pytest args...]
  --fast   skip scenarios marked slow and the isolated installs (they always run in CI)
"""

from __future__ import annotations

import glob
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent


#: The isolated installs: the kernel and one plugin distribution, each Python with the lowest or
#: the highest sibling versions their ranges allow.
ISOLATED = (("3.10", "lowest"), ("3.13", "highest"))
ISOLATED_PACKAGES = ("easynav-core", "easynav-common", "easynav-planners")


def find_python(version: str) -> str | None:
    """An interpreter of ``version`` (``3.10``): on PATH, or installed by pyenv."""
    candidates = [shutil.which(f"python{version}")]
    root = os.environ.get("PYENV_ROOT", os.path.expanduser("~/.pyenv"))
    candidates += sorted(glob.glob(f"{root}/versions/{version}.*/bin/python{version}"))
    for candidate in filter(None, candidates):
        probe = subprocess.run([candidate, "-c", "import sys; print(sys.version_info[:2])"],
                               capture_output=True, text=True)
        wanted = str(tuple(int(part) for part in version.split(".")))
        if probe.returncode == 0 and probe.stdout.strip() == wanted:
            return candidate
    return None


def isolated_installs(workers: str) -> int:
    """The kernel and a plugin distribution alone, on the oldest and the newest Python.

    The two run at once, each printed when it ends: building the message package (code
    generation, one process) and installing take most of each and leave a core idle (measured
    on 2 cores: 384 s for the pair, 531 s one after the other)."""
    runs = []
    for version, siblings in ISOLATED:
        python = find_python(version)
        if python is None:
            message = f"Python {version} not found: the isolated install on it did not run"
            print(message, flush=True)
            if os.environ.get("CI"):
                return 1
            continue
        title = (f"== isolated install of {', '.join(ISOLATED_PACKAGES)} on Python {version} "
                 f"({siblings} sibling versions)")
        log = tempfile.TemporaryFile(mode="w+")
        process = subprocess.Popen(
            [sys.executable, str(ROOT / "tools" / "release.py"), "isolated", *ISOLATED_PACKAGES,
             "--python", python, "--siblings", siblings, "--",
             "-q", "-m", "not slow", "-n", workers],
            cwd=ROOT, stdout=log, stderr=subprocess.STDOUT, text=True,
        )
        runs.append((title, process, log))
    code = 0
    for title, process, log in runs:
        returncode = process.wait()
        log.seek(0)
        print(title, flush=True)
        print(log.read(), end="", flush=True)
        log.close()
        if returncode != 0 and code == 0:
            code = returncode
    return code


def main(argv: list[str]) -> int:
    fast = "--fast" in argv
    extra = [a for a in argv if a != "--fast"]
    print("== ruff check", flush=True)
    lint = subprocess.run([str(BIN / "ruff"), "check", "."], cwd=ROOT)
    if lint.returncode != 0:
        print("ruff check failed", flush=True)
        return lint.returncode
    check = subprocess.run([sys.executable, str(ROOT / "tools" / "release.py"), "check"], cwd=ROOT)
    if check.returncode != 0:
        return check.returncode
    workers = os.environ.get("EASYNAV_TEST_WORKERS", "2")
    # The slowest tests' times in the log: what to look at first when the suite nears its budget.
    cmd = [sys.executable, "-m", "pytest", "-n", workers, "--dist", "loadgroup", "--durations=25"]
    if fast:
        cmd += ["-m", "not slow"]
    cmd += extra
    print("== " + " ".join(cmd[2:]), flush=True)
    result = subprocess.run(cmd, cwd=ROOT)
    if result.returncode == 5:  # pytest: no tests collected
        print("no tests were collected", flush=True)
        return 1
    if result.returncode != 0 or fast:
        return result.returncode
    return isolated_installs(workers)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
