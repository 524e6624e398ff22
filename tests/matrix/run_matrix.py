"""`make matrix`: run the whole integration matrix and write docs/matrix.md.

Usage: .venv/bin/python tests/matrix/run_matrix.py [--slice] [--worlds home,depot]
       [--speed-up 1.0] [--output docs/matrix.md] [--list]

  --slice   only the combinations that together use every plugin once (what CI runs)
  --list    print the combinations and exit
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from matrix import (  # noqa: E402 (the folder is not a package)
    ROOT,
    WORLDS,
    combinations,
    covering_slice,
    markdown,
    run_combination,
)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--slice", action="store_true")
    parser.add_argument("--worlds", default=",".join(WORLDS))
    parser.add_argument("--speed-up", type=float, default=1.0)
    parser.add_argument("--output", default=str(ROOT / "docs" / "matrix.md"))
    parser.add_argument("--list", action="store_true")
    args = parser.parse_args(argv)
    combos = combinations(tuple(w for w in args.worlds.split(",") if w))
    if args.slice:
        combos = covering_slice(combos)
    if args.list:
        for combo in combos:
            print(combo.name)
        print(f"{len(combos)} combinations")
        return 0
    started = datetime.now(timezone.utc)
    outcomes = []
    work = Path(tempfile.mkdtemp(prefix="easynav-matrix-"))
    for i, combo in enumerate(combos, 1):
        t0 = time.monotonic()
        outcome = run_combination(combo, work / f"{i:03d}", speed_up=args.speed_up)
        verdict = "green" if outcome.green else f"FAILED ({outcome.error})"
        print(f"[{i}/{len(combos)}] {combo.name}: {verdict} ({time.monotonic() - t0:.0f} s)",
              flush=True)
        outcomes.append(outcome)
    header = "\n".join([
        "# Integration matrix",
        "",
        "Written by `make matrix` (tests/matrix/run_matrix.py): every compatible combination of "
        "the installed maps managers, localizers, planners and controllers (compatibility as the "
        "plugins declare it) in each world, each a waypoint mission of the playground. CI runs "
        "the slice that uses every plugin at least once (`--slice`).",
        "",
        f"- date: {started:%Y-%m-%d %H:%M} UTC; Python {platform.python_version()}; "
        f"speed-up x{args.speed_up:g}; runs kept in {work}",
        "- this run: "
        + ("the covering slice only (`--slice`)" if args.slice else "every combination")
        + f", worlds {args.worlds}: {len(combos)} runs",
    ])
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(markdown(outcomes, header))
    print(f"wrote {args.output}")
    return 0 if all(o.green for o in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
