"""`make matrix`: run the whole integration matrix and write docs/matrix.md.

Usage: .venv/bin/python tests/matrix/run_matrix.py [--slice] [--worlds home,depot]
       [--speed-up 1.0] [--jobs 1] [--results FILE] [--output docs/matrix.md] [--list] [--report]

  --slice    only the combinations that together use every plugin once (CI runs them on the
             first 40 m of their world's tour; --slice drives the whole tour, as every row)
  --speed-up the simulation's speed (x real time; EasyNav's loops keep their wall-clock rates,
             so its RT cycles per simulated second drop by as much). On a 2-core machine one
             mission at x2 ran at x1.9-2.0 with the same verdict and figures as at x1 (the
             campus with MPPI and with VFF): `make matrix` runs it at x2, one at a time.
             At x4 a campus mission ran at x3.1-3.8 (EasyNav, not the simulator, takes the
             cores): half the time again, and a harder test (a quarter of the RT cycles per
             simulated second); docs/matrix.md has rows of x1, x2 and x4, each row says which
  --jobs N   N missions at once, each in a process of its own (a mission takes about a core
             at x1: N above the number of cores slows every run and can fail them)
  --results  where each finished run is kept, one JSON line per run (default
             docs/matrix.results.jsonl, kept in the repository with docs/matrix.md). A later
             call skips the combinations already there, so the full matrix (a thousand
             missions, more than a day of a 2-core machine) runs in parts, on any machine
             with a clone: stop it at any time (Ctrl-C or SIGTERM: runs in progress finish
             and are kept, queued ones do not start), commit the file, start it again. It
             runs again the rows kept stale (run with params since changed) and those kept
             overloaded faster than real time (these at x1; docs/matrix.md says why).
             docs/matrix.md is written from the file; each row names the commit it ran.
  --fresh    forget the results file first
  --only S   only the combinations whose name contains one of the comma-separated S
  --again S  run only the combinations whose name contains one of the comma-separated S, kept
             or not (a row that failed at x2, run again at x1: --again NAME --speed-up 1); the
             new run wins
  --list     print the combinations and exit
  --report   write docs/matrix.md from the results file without running anything
  --merge F  append to the results file the runs that results files F... (copies of it that
             went on elsewhere: another clone, another machine) hold and it does not, then
             write docs/matrix.md as --report does (of two runs of a combination the one that
             finished later counts). Merge a clone's file before resetting that clone, or its
             runs are lost

A failed row's verdict says what a user would notice first (collisions, waypoints missed, a
lost localisation, the run's message) and, when the failure was looked into, why:
tests/matrix/findings.yaml lists the causes found, each for the rows it explains; a failure
nobody looked into says so.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from datetime import datetime, timezone
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

from matrix import (  # noqa: E402 (the folder is not a package)
    LOST_LOCALISATION,
    OVERLOADED_ODOMETRY_AGE_MS,
    ROOT,
    WORLDS,
    Outcome,
    combinations,
    compose_params,
    covering_slice,
    failure,
    load_findings,
    markdown,
    odometry_lag,
    overloaded_fast,
    run_combination,
    unmatched_plugins,
)

DEFAULT_RESULTS = ROOT / "docs" / "matrix.results.jsonl"


def load_results(path: Path) -> dict[str, dict]:
    """The runs kept in ``path`` by combination name: of two runs of a name, the one finished
    later (``finished``, UTC), else the later line (rows kept before rows had the time); a
    line cut short by a stopped run is skipped. By time, a clone's older run merged after a
    newer one does not replace it."""
    found: dict[str, dict] = {}
    if not path.exists():
        return found
    for line in path.read_text().splitlines():
        try:
            row = json.loads(line)
            name = row["name"]
        except (ValueError, KeyError, TypeError):
            continue
        kept = found.get(name)
        if kept is None or not (kept.get("finished") and row.get("finished")
                                and row["finished"] < kept["finished"]):
            found[name] = row
    return found


def merge_results(path: Path, others: list[Path]) -> int:
    """Append to ``path`` every run line of ``others`` that it does not hold (the same line),
    in their order: copies of ``path`` that went on elsewhere add their runs, the newer of
    which win (:func:`load_results`). Returns the number of lines appended. Lines that are
    not a run (cut short, not JSON) are skipped."""
    have = set(path.read_text().splitlines()) if path.exists() else set()
    new: list[str] = []
    for other in others:
        for line in other.read_text().splitlines():
            try:
                json.loads(line)["name"]
            except (ValueError, KeyError, TypeError):
                continue
            if line not in have:
                have.add(line)
                new.append(line)
    if new:
        with path.open("a") as out:
            out.writelines(line + "\n" for line in new)
    return len(new)


def params_fingerprint(combo) -> str:
    """A short hash of the params document a combination runs with: a kept row whose params
    differ (a params file retuned, the composition changed) is stale and runs again."""
    text = yaml.safe_dump(compose_params(combo), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def stale_rows(combos, kept: dict[str, dict], fingerprints: dict[str, str]) -> set[str]:
    """The combinations kept with params other than they compose to now (no fingerprints: none).
    A row kept before rows had a fingerprint is stale too."""
    return {c.name for c in combos if fingerprints and c.name in kept
            and kept[c.name].get("params") != fingerprints[c.name]}


def overloaded_rows(kept: dict[str, dict]) -> set[str]:
    """The kept rows that ran faster than real time overloaded (:func:`matrix.odometry_lag`):
    they tested the machine, not the combination, and run again at x1."""
    return {name for name, row in kept.items()
            if overloaded_fast(row.get("summary") or {}, float(row.get("speed_up", 1.0)))}


def source_commit() -> str:
    """The commit the runs use (short hash, ``+changes`` when the tree differs from it): a row
    kept from an earlier part of the matrix says which code it ran."""
    def git(*args: str) -> str:
        done = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)
        return done.stdout.strip() if done.returncode == 0 else ""

    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    # docs/matrix.md and the results file are this runner's own output, not code the runs use.
    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".",
                  ":(exclude)docs/matrix.md", ":(exclude)docs/matrix.results.jsonl")
    return commit + ("+changes" if changed else "")


def run_one(name: str, run_dir: Path, speed_up: float, worlds: tuple[str, ...]) -> int:
    """``--run-one``: run one combination here and print its row as one JSON line."""
    # SIGTERM stops the mission the way Ctrl-C does: the demo stops the simulator and EasyNav
    # (the default action would leave them running, orphaned) and the row says "interrupted".
    signal.signal(signal.SIGTERM, _interrupt)
    combo = next((c for c in combinations(worlds) if c.name == name), None)
    if combo is None:
        print(json.dumps({"name": name, "exit_code": 2, "summary": {},
                          "error": "no such combination"}))
        return 2
    outcome = run_combination(combo, run_dir, speed_up=speed_up)
    print(json.dumps({"name": name, "exit_code": outcome.exit_code, "summary": outcome.summary,
                      "error": outcome.error, "run_dir": str(run_dir)}))
    return 0


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def _stopped_half_way(row: dict) -> bool:
    """A mission stopped from outside (Ctrl-C, SIGTERM) rather than ended: its row is not a
    result. A crash (another signal, an out-of-memory kill) is a result: a failure."""
    return (row.get("exit_code") in (130, -signal.SIGINT, -signal.SIGTERM)
            or row.get("summary", {}).get("final_state") == "INTERRUPTED")


def _run_in_process(name: str, run_dir: Path, args: argparse.Namespace,
                    speed_up: float) -> dict:
    """One combination in a process of its own (its own ROS domain, its own interpreter)."""
    cmd = [sys.executable, __file__, "--run-one", name, "--run-dir", str(run_dir),
           "--speed-up", str(speed_up), "--worlds", args.worlds]
    # A session of its own: Ctrl-C in the terminal stops the runner (which lets the runs in
    # progress finish and be kept), not the missions half-way, which would be kept as failures.
    done = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ),
                          start_new_session=True)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if lines:
        return json.loads(lines[-1])
    tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or [f"exit {done.returncode}"]
    return {"name": name, "exit_code": done.returncode or 1, "summary": {},
            "error": f"the harness failed: {tail[0]}", "run_dir": str(run_dir)}


def _ran(row: dict) -> str:
    """The report's "run" cell of a kept row: its commit and speed-up (``11a8747 x2``)."""
    return f"{row.get('commit', '?')} x{float(row.get('speed_up', 1.0)):g}"


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--slice", action="store_true")
    parser.add_argument("--worlds", default=",".join(WORLDS))
    parser.add_argument("--speed-up", type=float, default=1.0)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--report", action="store_true",
                        help="write --output from the results file, run nothing")
    parser.add_argument("--results", default=str(DEFAULT_RESULTS))
    parser.add_argument("--fresh", action="store_true")
    parser.add_argument("--only", default="")
    parser.add_argument("--again", default="")
    parser.add_argument("--output", default=str(ROOT / "docs" / "matrix.md"))
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--merge", nargs="+", default=[], metavar="FILE")
    parser.add_argument("--run-one", help=argparse.SUPPRESS)
    parser.add_argument("--run-dir", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    worlds = tuple(w for w in args.worlds.split(",") if w)
    if args.run_one:
        return run_one(args.run_one, Path(args.run_dir), args.speed_up, worlds)
    if args.jobs < 1:
        parser.error("--jobs must be >= 1")
    combos = combinations(worlds)
    unmatched = unmatched_plugins(combos)
    if args.slice:
        combos = covering_slice(combos)
    if args.only:
        wanted = [part for part in args.only.split(",") if part]
        combos = [c for c in combos if any(part in c.name for part in wanted)]
    if args.list:
        for combo in combos:
            print(combo.name)
        print(f"{len(combos)} combinations")
        for name, reason in sorted(unmatched.items()):
            print(f"in no combination: {name}: {reason}")
        return 0

    findings = load_findings()  # a malformed file is refused now, not after hours of runs
    results_path = Path(args.results)
    results_path.parent.mkdir(parents=True, exist_ok=True)
    if args.fresh:
        results_path.unlink(missing_ok=True)
    if args.merge:
        appended = merge_results(results_path, [Path(p) for p in args.merge])
        print(f"merged {appended} runs into {results_path}", flush=True)
        args.report = True
    kept = load_results(results_path)
    # The report needs the fingerprints of the kept rows only (a stale row says so); a run
    # needs every combination's, to keep them in its rows.
    fingerprints = {c.name: params_fingerprint(c) for c in combos
                    if not args.report or c.name in kept}
    stale = stale_rows(combos, kept, fingerprints)
    # A row overloaded faster than real time runs again at x1 (faster, it would only be
    # overloaded again), stale or not; it is counted once, as stale when it is both.
    rerun_at_x1 = {c.name for c in combos if c.name in kept} & overloaded_rows(kept)
    overloaded = rerun_at_x1 - stale
    again = [part for part in args.again.split(",") if part]
    if args.report:
        todo = []
    elif again:
        todo = [c for c in combos if any(part in c.name for part in again)]
    else:
        todo = [c for c in combos if c.name not in kept or c.name in stale | overloaded]
    done_before = sum(c.name in kept for c in combos) - len(stale | overloaded)
    print(f"{len(combos)} combinations: {done_before} done in {results_path}, {len(stale)} "
          f"kept there with other params, {len(overloaded)} overloaded faster than real time "
          f"(both to run again), {len(todo)} to run, {args.jobs} at a time", flush=True)
    started = datetime.now(timezone.utc)
    commit = source_commit()
    work = Path(tempfile.mkdtemp(prefix="easynav-matrix-"))
    lock = threading.Lock()
    finished = [0]

    def run(index_combo: tuple[int, object]) -> None:
        i, combo = index_combo
        t0 = time.monotonic()
        # --again runs at the speed asked for (a row retested at x4 after a fix).
        speed_up = (min(args.speed_up, 1.0) if combo.name in rerun_at_x1 and not again
                    else args.speed_up)
        row = _run_in_process(combo.name, work / f"{i:03d}", args, speed_up)
        row["seconds"] = round(time.monotonic() - t0, 1)
        row["commit"] = commit
        row["params"] = fingerprints[combo.name]
        row["speed_up"] = speed_up
        row["finished"] = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        run_dir = row.pop("run_dir", "")  # a temporary folder: not kept in the row
        if _stopped_half_way(row):  # a mission killed on its own is no result: run it again
            print(f"[-] {combo.name}: stopped before its end ({row['error']}), not kept",
                  flush=True)
            return
        with lock:
            with results_path.open("a") as f:
                f.write(json.dumps(row) + "\n")
            kept[combo.name] = row
            finished[0] += 1
            outcome = Outcome(combo, row["exit_code"], row["summary"], row["error"],
                              speed_up=speed_up)
            if outcome.overloaded_fast:
                said = (f"overloaded (EasyNav's TF listener handled odom → robot "
                        f"{odometry_lag(row['summary']):.0f} ms after its stamp, median; more "
                        f"than {OVERLOADED_ODOMETRY_AGE_MS:g} ms): to run again at x1")
            elif outcome.green:
                said = "green"
            else:
                said = f"FAILED ({failure(outcome)}; the run: {run_dir})"
            if outcome.green:  # its logs and picture are kept for failures only (2.5 MB a run)
                shutil.rmtree(work / f"{i:03d}", ignore_errors=True)
            print(f"[{finished[0]}/{len(todo)}] {combo.name}: {said} ({row['seconds']:.0f} s "
                  f"at x{speed_up:g})", flush=True)

    # SIGTERM (a job's time limit, `kill`) stops it the way Ctrl-C does.
    signal.signal(signal.SIGTERM, _interrupt)
    pool = ThreadPoolExecutor(max_workers=args.jobs)
    try:
        for future in [pool.submit(run, item) for item in enumerate(todo, 1)]:
            future.result()
    except KeyboardInterrupt:
        print("interrupted: waiting for the runs in progress; the finished runs are kept, run "
              "again to go on", flush=True)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)  # queued runs never start
    stale = stale_rows(combos, kept, fingerprints)  # the runs of this call are not
    overloaded = ({c.name for c in combos if c.name in kept} & overloaded_rows(kept)) - stale
    outcomes = [
        Outcome(c, kept[c.name]["exit_code"], kept[c.name]["summary"], kept[c.name]["error"],
                ran=_ran(kept[c.name]), stale=c.name in stale,
                speed_up=float(kept[c.name].get("speed_up", 1.0)))
        for c in combos if c.name in kept
    ]
    commits: dict[str, int] = {}
    speeds: dict[float, int] = {}
    for c in combos:
        if c.name in kept:
            key = kept[c.name].get("commit", "not recorded")
            commits[key] = commits.get(key, 0) + 1
            speed = float(kept[c.name].get("speed_up", 1.0))
            speeds[speed] = speeds.get(speed, 0) + 1
    header = "\n".join([
        "# Integration matrix",
        "",
        "Written by `make matrix` (tests/matrix/run_matrix.py): every compatible combination of "
        "the installed maps managers, localizers, planners and controllers (compatibility as the "
        "plugins declare it) in each world, each a waypoint mission of the playground. CI runs "
        "the combinations that together use every plugin at least once (`--slice` lists them), "
        "each in the first world that suits it (home, the campus for the plugins that need its "
        "sensors), on the legs of that world's tour that fit in its first 40 m (home's whole "
        "tour, the campus's first leg). Each plugin is configured "
        "as in a params file written for the row's world where there is one (`# Run: ... "
        "--world NAME`: the tb3_sandbox's costmap files, the depot's costmap with its keepout "
        "and speed zones, the campus's files for the Simple* plugins), else as in the "
        "playground's file or the first file under params/ that uses it. A failed row says what "
        "a user would notice first and, once looked into, why (tests/matrix/findings.yaml). "
        "A row run N times faster than real time (`--speed-up N`: 2 or 4) drives the same "
        "mission in simulated time, but EasyNav's loops keep their wall-clock rates: its RT "
        "cycles per simulated second are divided by N (a controller or smoother set faster "
        "than that runs slower), and every computation takes N times as long in simulated "
        "time, a harder test of the combination, not an easier one. A row that fails so is "
        "run again at x1 before it is looked into. Columns: the time of the mission is simulated; "
        "the minimum clearance is the robot's over the mission; the localisation error is "
        "EasyNav's estimate against the truth over the whole run, from its first estimate (a "
        f"row whose error ever exceeds {LOST_LOCALISATION:g} m fails: the robot was lost, even "
        "if it got there); "
        "late RT cycles (EasyNav's heartbeat) are those that started more than "
        "`safety.rt_monitor.max_period_factor` (2) periods after the previous one, from "
        "EasyNav's activation on; run: the commit and the speed-up the row ran with. A row "
        "kept from a run whose params the combination no longer composes to (a params file "
        "retuned since) is marked stale: it runs again with the next `make matrix`. A run "
        "in which EasyNav's TF listener handled the odom → robot transforms more than "
        f"{OVERLOADED_ODOMETRY_AGE_MS:g} ms after their stamps (median, simulated time) was "
        "overloaded: "
        "the machine could not keep up, and the stack drove on a TF tree that much in the "
        "past (laser scans drawn with an old pose, off the walls). Faster than real time, "
        "such a run tested the machine, not the combination: it is marked overloaded and "
        "runs again at x1 with the next `make matrix`; in real time its verdict says so.",
        "",
        (f"- date: {started:%Y-%m-%d %H:%M} UTC, written from {results_path.name} (nothing run)"
         if args.report else
         f"- date: {started:%Y-%m-%d %H:%M} UTC (rows of earlier parts come from "
         f"{results_path.name}); Python {platform.python_version()}; speed-up "
         f"x{args.speed_up:g}; {args.jobs} run(s) at a time"),
        "- this run: "
        + ("the covering slice only (`--slice`)" if args.slice else "every combination")
        + (f" whose name contains {args.only}" if args.only else "")
        + f", worlds {args.worlds}: {sum(not o.to_run_again for o in outcomes)} of "
        f"{len(combos)} runs done"
        + (" (" + "; ".join(
            ([f"{len(stale)} more kept stale: to run again"] if stale else [])
            + ([f"{len(overloaded)} more kept overloaded faster than real time: to run again "
                "at x1"] if overloaded else [])) + ")" if stale or overloaded else ""),
        "- code of the rows: "
        + (", ".join(f"{key} ({n} rows)" for key, n in sorted(commits.items())) or "none yet"),
        "- speed-up of the rows: "
        + (", ".join(f"x{key:g} ({n} rows)" for key, n in sorted(speeds.items())) or "none yet"),
    ])
    Path(args.output).parent.mkdir(parents=True, exist_ok=True)
    Path(args.output).write_text(markdown(outcomes, header, unmatched, findings))
    print(f"wrote {args.output}")
    return 0 if len(outcomes) == len(combos) and all(
        o.green and not o.to_run_again for o in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
