"""The whole test suite: ruff over the tree, then pytest over every package and tests/.

Usage: .venv/bin/python tools/run_tests.py [--fast] [pytest args...]
  --fast   skip scenarios marked slow (they always run in CI)
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent


def main(argv: list[str]) -> int:
    fast = "--fast" in argv
    extra = [a for a in argv if a != "--fast"]
    print("== ruff check", flush=True)
    lint = subprocess.run([str(BIN / "ruff"), "check", "."], cwd=ROOT)
    if lint.returncode != 0:
        print("ruff check failed", flush=True)
        return lint.returncode
    workers = os.environ.get("EASYNAV_TEST_WORKERS", "2")
    cmd = [sys.executable, "-m", "pytest", "-n", workers, "--dist", "loadgroup"]
    if fast:
        cmd += ["-m", "not slow"]
    cmd += extra
    print("== " + " ".join(cmd[2:]), flush=True)
    result = subprocess.run(cmd, cwd=ROOT)
    if result.returncode == 5:  # pytest: no tests collected
        print("no tests were collected", flush=True)
        return 1
    return result.returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
