"""Run every benchmark script of every package and write one table: docs/benchmarks.md.

Usage: .venv/bin/python tools/run_benchmarks.py [--only SUBSTRING] [--output PATH] [--append]

Finds ``packages/*/benchmarks/bench_*.py`` and ``benchmarks/bench_*.py``, runs each in its own
process with ``--json`` (the project's benchmark convention: rows of figure, value, unit,
reference, reference value, ratio, goal, met), one after the other so they do not load each
other, and writes a Markdown table with the machine, the date and the load it ran under. A
script that fails or times out gets a row saying so, with the tail of its output.
``--append`` adds the run as a section of its own (its date, commit and load) at the end of the
existing file instead of replacing it: for benchmarks added after the last complete run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import signal
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Per script. The whole-stack benchmark alone patrols 3 + 2 x 10 simulated minutes at real
#: time (about 35 min with start-up); the others take seconds to a few minutes.
TIMEOUT = 2700.0


def scripts(only: str | None) -> list[Path]:
    found = sorted(ROOT.glob("packages/*/benchmarks/bench_*.py")) + sorted(
        ROOT.glob("benchmarks/bench_*.py")
    )
    return [p for p in found if only is None or only in str(p)]


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def stop_group(proc: subprocess.Popen) -> None:
    """SIGINT to the script's process group (its children clean up), SIGKILL after 20 s."""
    for sig, wait in ((signal.SIGINT, 20.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.communicate(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def run_one(script: Path) -> tuple[list[dict], str, float]:
    """The script's rows, an error text ("" when it ran), and its wall time."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "rows.json"
        start = time.monotonic()
        # Its own process group: a script that times out is stopped with the processes it
        # started (the whole-stack benchmark's EasyNav and playground kept running, and
        # loading the machine, after a timeout killed only the script).
        proc = subprocess.Popen(
            [sys.executable, str(script), "--json", str(out)], cwd=ROOT,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        )
        try:
            stdout, stderr = proc.communicate(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            stop_group(proc)
            return [], f"timed out after {TIMEOUT:.0f} s", time.monotonic() - start
        took = time.monotonic() - start
        sys.stdout.write(stdout[-4000:])
        if proc.returncode != 0 or not out.exists():
            tail = (stderr or stdout).strip().splitlines()[-3:]
            return [], f"exit {proc.returncode}: " + " / ".join(tail), took
        return json.loads(out.read_text()), "", took


def cell(value) -> str:
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
    return str(value).replace("|", "\\|")


def markdown(results: list[tuple[Path, list[dict], str, float]], header: list[str]) -> str:
    lines = header + [
        "",
        "| script | figure | value | unit | reference | ref. value | ratio | goal | met |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    met = missed = 0
    for script, rows, error, _ in results:
        name = str(script.relative_to(ROOT))
        if error:
            lines.append(f"| `{name}` | **did not run** | | | | | | {cell(error)} | NO |")
            missed += 1
            continue
        for row in rows:
            verdict = row.get("met")
            if verdict is True:
                met += 1
            elif verdict is False:
                missed += 1
            mark = "—" if verdict is None else ("yes" if verdict else "**NO**")
            lines.append(
                f"| `{name}` | {cell(row['figure'])} | {cell(row['value'])} | "
                f"{cell(row['unit'])} | {cell(row.get('reference') or None)} | "
                f"{cell(row.get('reference_value'))} | {cell(row.get('ratio'))} | "
                f"{cell(row.get('goal') or None)} | {mark} |"
            )
    lines += ["", f"Goals met: {met}; missed or not run: {missed}.", ""]
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run only scripts whose path contains this")
    parser.add_argument("--output", default=str(ROOT / "docs" / "benchmarks.md"))
    parser.add_argument(
        "--append", action="store_true",
        help="add this run as a section at the end of --output instead of replacing it",
    )
    args = parser.parse_args(argv)
    load_before = os.getloadavg()[0]
    started = datetime.now(timezone.utc)
    results = []
    for script in scripts(args.only):
        print(f"== {script.relative_to(ROOT)}", flush=True)
        rows, error, took = run_one(script)
        if error:
            print(f"   FAILED: {error}", flush=True)
        results.append((script, rows, error, took))
    commit = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    header = [
        "# Benchmarks",
        "",
        "Written by `make bench` (tools/run_benchmarks.py): every benchmark script of every "
        "package, each comparing this project's figure with a reference measured in the same "
        "run on the same input. Ratios travel between machines better than times do.",
        "",
        f"- date: {started:%Y-%m-%d %H:%M} UTC; commit {commit or 'unknown'}",
        f"- machine: {cpu_model()}, {os.cpu_count()} CPUs, {platform.system()} "
        f"{platform.release()}, Python {platform.python_version()}",
        f"- load average (1 min) before: {load_before:.2f}, after: {os.getloadavg()[0]:.2f} "
        "(a shared machine: other processes take cores, which widens the p99 figures)",
        "- scripts: " + ", ".join(f"`{s.relative_to(ROOT)}` ({t:.0f} s)" for s, _, _, t in results),
    ]
    output = Path(args.output)
    if args.append and output.exists():
        header[0] = f"## Later run: scripts matching `{args.only or ''}`"
        header[2] = "Run after the table above, on the same kind of machine; its own conditions:"
        text = output.read_text().rstrip("\n") + "\n\n" + markdown(results, header)
    else:
        text = markdown(results, header)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(text)
    print(f"\nwrote {args.output}")
    return 0 if all(not error for _, _, error, _ in results) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
