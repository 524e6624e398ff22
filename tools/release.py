"""Release tooling: each distribution is versioned, built and tested on its own.

Usage: .venv/bin/python tools/release.py COMMAND ...

  check                      every package: a version, a CHANGELOG section for it, a tested
                             range (lower and upper bound) on every dependency, and every
                             sibling range admitting the sibling's current version
  build [PKG ...]            wheel + sdist of each package (all by default) into dist/
  bump PKG {major,minor,patch}
                             new version of one package (pyproject + a CHANGELOG section);
                             refused when a dependent's range would not admit it
  isolated PKG [PKG ...] [--python PY] [--siblings lowest|highest] [-- PYTEST_ARGS]
                             a fresh virtual environment with only the PKGs' wheels, their
                             declared dependencies and the wheels of the siblings they declare
                             (at the lowest or highest version the ranges allow); the PKGs'
                             own tests there
  isolated-all [--python PY]  every package alone, against the lowest and the highest
                             sibling versions (the whole range check; long)

Sibling versions: "highest" is the repository's current version of each sibling; "lowest" is the
sibling as it was at the newest commit whose version equals the range's lower bound (found in the
git history), so a package is tested against the oldest sibling it claims to work with.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.version import Version

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ROOT / "packages"
DIST = ROOT / "dist"
VERSION_LINE = re.compile(r'^version = "([^"]+)"$', re.M)


class ReleaseError(RuntimeError):
    """A check failed or a command cannot be carried out; the message says why."""


@dataclass
class Package:
    """One distribution of the monorepo: its folder, name, version and requirements."""

    folder: Path
    name: str
    version: Version
    requirements: list[Requirement] = field(default_factory=list)
    extras: dict[str, list[Requirement]] = field(default_factory=dict)

    @property
    def pyproject(self) -> Path:
        return self.folder / "pyproject.toml"

    @property
    def changelog(self) -> Path:
        return self.folder / "CHANGELOG.md"

    def all_requirements(self) -> list[Requirement]:
        reqs = list(self.requirements)
        for extra in self.extras.values():
            reqs += extra
        return reqs


def load_packages(root: Path = PACKAGES) -> dict[str, Package]:
    """Every package of the monorepo by distribution name."""
    packages = {}
    for pyproject in sorted(root.glob("*/pyproject.toml")):
        project = tomllib.loads(pyproject.read_text())["project"]
        packages[project["name"]] = Package(
            pyproject.parent,
            project["name"],
            Version(project["version"]),
            [Requirement(r) for r in project.get("dependencies", [])],
            {
                name: [Requirement(r) for r in reqs]
                for name, reqs in project.get("optional-dependencies", {}).items()
            },
        )
    return packages


def lower_bound(spec: SpecifierSet) -> Version | None:
    """The inclusive lower bound of a range (``>=`` or ``~=``), or None."""
    bounds = [Version(s.version) for s in spec if s.operator in (">=", "~=", "==")]
    return max(bounds) if bounds else None


def has_upper_bound(spec: SpecifierSet) -> bool:
    """Whether a range has an upper bound (``<``, ``<=``, ``~=`` or ``==``)."""
    return any(s.operator in ("<", "<=", "~=", "==") for s in spec)


def check(packages: dict[str, Package]) -> list[str]:
    """Every inconsistency of the set, in words (empty when consistent)."""
    problems = []
    for pkg in packages.values():
        if not pkg.changelog.is_file():
            problems.append(f"{pkg.name}: no CHANGELOG.md")
        elif f"## {pkg.version}" not in pkg.changelog.read_text():
            problems.append(f"{pkg.name}: CHANGELOG.md has no section '## {pkg.version}'")
        for req in pkg.all_requirements():
            where = f"{pkg.name}: dependency '{req}'"
            if req.name in packages:
                sibling = packages[req.name]
                if not req.specifier:
                    problems.append(f"{where} has no version range")
                elif not req.specifier.contains(sibling.version, prereleases=True):
                    problems.append(
                        f"{where} does not admit {req.name} {sibling.version} (the repository's)"
                    )
                elif not has_upper_bound(req.specifier):
                    problems.append(f"{where} has no upper bound")
                continue
            if lower_bound(req.specifier) is None or not has_upper_bound(req.specifier):
                problems.append(f"{where} needs a tested range: a lower and an upper bound")
    return problems


def dependents(packages: dict[str, Package], name: str) -> list[tuple[Package, Requirement]]:
    """The packages that declare ``name``, with their requirement."""
    return [
        (pkg, req)
        for pkg in packages.values()
        for req in pkg.all_requirements()
        if req.name == name
    ]


def bump(packages: dict[str, Package], name: str, level: str) -> Version:
    """Write the next version of ``name``; refuses (ReleaseError) an inconsistent set."""
    if name not in packages:
        raise ReleaseError(f"no package {name!r}; packages: {', '.join(sorted(packages))}")
    pkg = packages[name]
    major, minor, patch = (list(pkg.version.release) + [0, 0])[:3]
    new = {
        "major": Version(f"{major + 1}.0.0"),
        "minor": Version(f"{major}.{minor + 1}.0"),
        "patch": Version(f"{major}.{minor}.{patch + 1}"),
    }[level]
    refused = [
        f"{dep.name} requires '{req}'"
        for dep, req in dependents(packages, name)
        if not req.specifier.contains(new, prereleases=True)
    ]
    if refused:
        raise ReleaseError(
            f"{name} {new} would leave an inconsistent set: " + "; ".join(refused)
            + ". Widen those ranges (and test them) first."
        )
    text = pkg.pyproject.read_text()
    pkg.pyproject.write_text(VERSION_LINE.sub(f'version = "{new}"', text, count=1))
    changelog = pkg.changelog.read_text() if pkg.changelog.is_file() else f"# {name}\n"
    head, _, rest = changelog.partition("\n## ")
    section = f"## {new}\n\n- (describe the changes of this release)\n"
    pkg.changelog.write_text(f"{head.rstrip()}\n\n{section}\n" + (f"## {rest}" if rest else ""))
    return new


def build(packages: dict[str, Package], names: list[str], out: Path = DIST) -> list[Path]:
    """Wheel and sdist of each named package into ``out``; returns the files made."""
    out.mkdir(parents=True, exist_ok=True)
    made = []
    for name in names or sorted(packages):
        if name not in packages:
            raise ReleaseError(f"no package {name!r}")
        made += build_folder(packages[name].folder, out)
    return made


def build_folder(folder: Path, out: Path, python: str = sys.executable) -> list[Path]:
    """Wheel and sdist of the package in ``folder``. The message package builds with this
    environment's build tools (no isolation: the ROS build wheels are large)."""
    before = set(out.glob("*"))
    isolation = ["--no-isolation"] if (folder / "setup.py").exists() else []
    result = subprocess.run(
        [python, "-m", "build", "--sdist", "--wheel", "--outdir", str(out), *isolation,
         str(folder)],
        capture_output=True, text=True, env=clean_environment(),
    )
    if result.returncode != 0:
        raise ReleaseError(f"building {folder.name} failed:\n{result.stdout[-3000:]}"
                           f"\n{result.stderr[-3000:]}")
    return sorted(set(out.glob("*")) - before)


def commit_with_version(pkg: Package, version: Version) -> str | None:
    """The newest commit whose pyproject of ``pkg`` has ``version`` (None when none has)."""
    rel = pkg.pyproject.relative_to(ROOT)
    log = subprocess.run(
        ["git", "log", "--format=%H", "--", str(rel)], cwd=ROOT, capture_output=True, text=True
    ).stdout.split()
    for commit in log:
        text = subprocess.run(
            ["git", "show", f"{commit}:{rel}"], cwd=ROOT, capture_output=True, text=True
        ).stdout
        match = VERSION_LINE.search(text)
        if match and Version(match.group(1)) == version:
            return commit
    return None


def sibling_folder(pkg: Package, req: Requirement, siblings: str, work: Path) -> Path:
    """The source folder of sibling ``pkg`` at the version ``siblings`` asks for."""
    if siblings == "highest":
        return pkg.folder
    low = lower_bound(req.specifier)
    if low is None or low == pkg.version:
        return pkg.folder
    commit = commit_with_version(pkg, low)
    if commit is None:
        raise ReleaseError(f"{req}: no commit of the history has {pkg.name} {low}")
    target = work / f"{pkg.name}-{low}"
    target.mkdir(parents=True)
    archive = subprocess.run(
        ["git", "archive", commit, str(pkg.folder.relative_to(ROOT))],
        cwd=ROOT, capture_output=True, check=True,
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(target)], input=archive, check=True)
    return target / pkg.folder.relative_to(ROOT)


def source_copy(folder: Path, into: Path) -> Path:
    """A copy of the package source ``folder`` under ``into``: the files git lists there
    (tracked, and untracked ones git does not ignore), symlinks as the files they point to.
    The build in the repository sees the same files (hatchling leaves out what ``.gitignore``
    names; a copy outside the repository has no ``.gitignore`` above it), and none of what an
    earlier build left (``build/``, ``*.egg-info``: ignored). Returns the copy's path."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard", "--", "."],
        cwd=folder, capture_output=True, check=True,
    ).stdout
    target = into / folder.name
    for name in filter(None, listed.split(b"\0")):
        source = folder / os.fsdecode(name)
        if not source.is_file():
            continue  # deleted in the work tree, not yet in git
        copy = target / os.fsdecode(name)
        copy.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, copy)
    return target


def closure(
    packages: dict[str, Package], names: list[str]
) -> list[tuple[Package, Requirement | None]]:
    """The named packages and every sibling they need, directly or through another sibling
    (with the requirement that brought it in; None for the named ones)."""
    seen: dict[str, tuple[Package, Requirement | None]] = {n: (packages[n], None) for n in names}
    # The named packages' test extras may name siblings too (a plugin distribution's ROS tests
    # need easynav-system[test], whose safety tests inject faults with easynav-faulty); so may
    # any extra a requirement asks for: those siblings are built as well.
    queue: list[list[Requirement]] = [packages[n].requirements for n in names]
    queue += [packages[n].extras.get("test", []) for n in names]
    followed: set[tuple[str, str]] = set()
    while queue:
        for req in queue.pop():
            if req.name not in packages:
                continue
            sibling = packages[req.name]
            if req.name not in seen:
                seen[req.name] = (sibling, req)
                queue.append(sibling.requirements)
            for extra in req.extras:
                if (req.name, extra) not in followed:
                    followed.add((req.name, extra))
                    queue.append(sibling.extras.get(extra, []))
    return list(seen.values())


def isolated(
    packages: dict[str, Package],
    names: list[str],
    python: str,
    siblings: str,
    pytest_args: list[str],
) -> int:
    """Install the named packages alone (with their declared dependencies) in a fresh venv;
    run their tests there."""
    for name in names:
        if name not in packages:
            raise ReleaseError(f"no package {name!r}")
    work = Path(tempfile.mkdtemp(prefix="easynav-isolated-"))
    started = time.monotonic()
    spent: dict[str, float] = {}  # seconds per wheel built (and the build environment)
    try:
        wheels = work / "wheels"
        for pkg, req in closure(packages, names):
            folder = pkg.folder if req is None else sibling_folder(pkg, req, siblings, work)
            if folder == pkg.folder:
                # Built from a copy: setuptools builds in the source folder (build/, egg-info),
                # and the isolated installs run at once; two builds in one folder collide.
                folder = source_copy(pkg.folder, work / "sources")
            # The message package has compiled parts: built by the target Python, in a build
            # environment of its own unless that Python is this one.
            builder = sys.executable
            step = time.monotonic()
            if (folder / "setup.py").exists() and not same_python(python, sys.executable):
                builder = build_environment(python, work, folder)
                spent["build environment"] = time.monotonic() - step
                step = time.monotonic()
            build_folder(folder, wheels, builder)
            spent[pkg.name] = time.monotonic() - step
        built = time.monotonic()
        venv = work / "venv"
        run([python, "-m", "venv", str(venv)])
        vpy = str(venv / "bin" / "python")
        run([vpy, "-m", "pip", "install", "--quiet", "--upgrade", "pip"])
        targets = []
        for name in names:
            pkg = packages[name]
            extra = "[test]" if "test" in pkg.extras else ""
            wheel = next(wheels.glob(pkg.name.replace("-", "_") + "-*.whl"))
            targets.append(f"{wheel}{extra}")
        if not any("test" in packages[name].extras for name in names):
            # No test extra of their own: the kernel's brings the test tools.
            core = next(wheels.glob("easynav_core-*.whl"))
            targets.append(f"{core}[test]")
        run([vpy, "-m", "pip", "install", "--quiet", "--find-links", str(wheels), *targets])
        listed = run([vpy, "-m", "pip", "list", "--format=freeze"]).stdout
        ours = sorted(line for line in listed.splitlines() if line.lower().startswith("easynav"))
        version = run([vpy, "--version"]).stdout.strip()
        installed = time.monotonic()
        print(f"[isolated] {', '.join(names)} on {version} ({siblings} siblings): "
              + ", ".join(ours), flush=True)
        slowest = ", ".join(f"{name} {seconds:.0f} s" for name, seconds in
                            sorted(spent.items(), key=lambda item: -item[1])[:3])
        print(f"[isolated] wheels built in {built - started:.0f} s ({slowest}), installed in "
              f"{installed - built:.0f} s", flush=True)
        env = clean_environment()
        # From a copy of the tests outside the repository: nothing but the installed wheels is
        # importable (the repository's conftest gives each test process its ROS domain).
        shutil.copy(ROOT / "conftest.py", work / "conftest.py")
        for name in names:
            shutil.copytree(packages[name].folder / "tests", work / "tests" / name)
        (work / "pytest.ini").write_text(
            "[pytest]\naddopts = -ra --import-mode=importlib -p no:cacheprovider\n"
            "timeout = 300\nmarkers =\n  slow: long\n  ros: ROS\n  rt: real time\n"
            "filterwarnings =\n  ignore:module 'sre_:DeprecationWarning\n"
        )
        code = subprocess.run(
            [vpy, "-m", "pytest", "-q", *pytest_args, "tests"], cwd=work, env=env
        ).returncode
        print(f"[isolated] tests ran in {time.monotonic() - installed:.0f} s", flush=True)
        return code
    finally:
        shutil.rmtree(work, ignore_errors=True)


def clean_environment() -> dict[str, str]:
    """This process's environment without what the ROS wheels' start-up set for *this* venv
    (its library path and the guard that says it is set): a Python of another venv must set
    its own, or rclpy there loads this venv's libraries."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE", "VIRTUAL_ENV")}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def same_python(a: str, b: str) -> bool:
    """Whether two interpreters are the same Python version."""
    version = "import sys; print(sys.version_info[:2])"
    return run([a, "-c", version]).stdout == run([b, "-c", version]).stdout


def build_environment(python: str, work: Path, folder: Path) -> str:
    """A venv of ``python`` with the message package's build requirements; its interpreter."""
    venv = work / "build-venv"
    vpy = str(venv / "bin" / "python")
    if not (venv / "bin" / "python").exists():
        run([python, "-m", "venv", str(venv)])
        run([vpy, "-m", "pip", "install", "--quiet", "--upgrade", "pip", "build", "wheel",
             "setuptools>=77"])
        run([vpy, "-m", "pip", "install", "--quiet", "-r",
             str(folder / "tools" / "build_requirements.txt")])
    return vpy


def run(cmd: list[str]) -> subprocess.CompletedProcess:
    result = subprocess.run(cmd, capture_output=True, text=True, env=clean_environment())
    if result.returncode != 0:
        raise ReleaseError(f"{' '.join(cmd)} failed:\n{result.stdout[-3000:]}"
                           f"\n{result.stderr[-3000:]}")
    return result


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("check")
    p_build = sub.add_parser("build")
    p_build.add_argument("packages", nargs="*")
    p_bump = sub.add_parser("bump")
    p_bump.add_argument("package")
    p_bump.add_argument("level", choices=("major", "minor", "patch"))
    p_iso = sub.add_parser("isolated")
    p_iso.add_argument("package", nargs="+")
    p_iso.add_argument("--python", default=sys.executable)
    p_iso.add_argument("--siblings", choices=("lowest", "highest"), default="highest")
    p_all = sub.add_parser("isolated-all")
    p_all.add_argument("--python", default=sys.executable)
    # Everything after "--" goes to pytest.
    pytest_args: list[str] = []
    if "--" in argv:
        argv, pytest_args = argv[: argv.index("--")], argv[argv.index("--") + 1 :]
    args = parser.parse_args(argv)
    packages = load_packages()
    try:
        if args.command == "check":
            problems = check(packages)
            for problem in problems:
                print(f"release check: {problem}", file=sys.stderr)
            if not problems:
                print(f"release check: {len(packages)} packages consistent")
            return 1 if problems else 0
        if args.command == "build":
            for path in build(packages, args.packages):
                print(path.relative_to(ROOT) if path.is_relative_to(ROOT) else path)
            return 0
        if args.command == "bump":
            problems = check(packages)
            if problems:
                raise ReleaseError("the set is inconsistent already: " + "; ".join(problems))
            new = bump(packages, args.package, args.level)
            print(f"{args.package} {new}: edit its CHANGELOG.md section, then commit")
            return 0
        if args.command == "isolated-all":
            failed = []
            # A distribution without tests (the meta-distribution easynav) has nothing to run.
            for name in sorted(n for n in packages if (packages[n].folder / "tests").is_dir()):
                for siblings in ("lowest", "highest"):
                    code = isolated(packages, [name], args.python, siblings,
                                    pytest_args or ["-q", "-m", "not slow", "-n", "2"])
                    if code != 0:
                        failed.append(f"{name} ({siblings} siblings): exit {code}")
            for line in failed:
                print(f"release isolated-all: FAILED {line}", file=sys.stderr)
            return 1 if failed else 0
        return isolated(packages, args.package, args.python, args.siblings, pytest_args)
    except ReleaseError as exc:
        print(f"release: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
