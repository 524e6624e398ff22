"""tools/release.py: the consistency check, the refused bump, and the repository's own set."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("release", REPO / "tools" / "release.py")
release = importlib.util.module_from_spec(spec)
sys.modules["release"] = release
spec.loader.exec_module(release)


def write_package(root: Path, name: str, version: str, deps: list[str], changelog=True) -> None:
    folder = root / name
    folder.mkdir(parents=True)
    quoted = ", ".join(f'"{d}"' for d in deps)
    (folder / "pyproject.toml").write_text(
        f'[project]\nname = "{name}"\nversion = "{version}"\ndependencies = [{quoted}]\n'
    )
    if changelog:
        (folder / "CHANGELOG.md").write_text(f"# {name}\n\n## {version}\n\n- first\n")


@pytest.fixture
def monorepo(tmp_path):
    write_package(tmp_path, "easynav-core", "0.1.0", ["numpy>=1.26,<3"])
    write_package(tmp_path, "easynav-maps", "0.1.0", ["easynav-core>=0.1.0,<0.2"])
    return tmp_path


def test_the_repository_set_is_consistent():
    assert release.check(release.load_packages()) == []


def test_a_consistent_set_passes(monorepo):
    assert release.check(release.load_packages(monorepo)) == []


def test_unbounded_and_unpinned_dependencies_are_named(tmp_path):
    write_package(tmp_path, "easynav-core", "0.1.0", ["numpy>=1.26"], changelog=False)
    write_package(tmp_path, "easynav-maps", "0.1.0", ["easynav-core", "opencv-python-headless"])
    problems = release.check(release.load_packages(tmp_path))
    assert "easynav-core: no CHANGELOG.md" in problems
    assert ("easynav-core: dependency 'numpy>=1.26' needs a tested range: a lower and an "
            "upper bound") in problems
    assert "easynav-maps: dependency 'easynav-core' has no version range" in problems


def test_a_sibling_range_that_excludes_the_sibling_is_named(tmp_path):
    write_package(tmp_path, "easynav-core", "0.2.0", [])
    write_package(tmp_path, "easynav-maps", "0.1.0", ["easynav-core>=0.1.0,<0.2"])
    assert release.check(release.load_packages(tmp_path)) == [
        "easynav-maps: dependency 'easynav-core<0.2,>=0.1.0' does not admit easynav-core 0.2.0 "
        "(the repository's)"
    ]


def test_a_bump_a_dependent_does_not_admit_is_refused(monorepo):
    packages = release.load_packages(monorepo)
    with pytest.raises(release.ReleaseError, match=r"easynav-maps requires 'easynav-core"):
        release.bump(packages, "easynav-core", "minor")
    assert 'version = "0.1.0"' in (monorepo / "easynav-core" / "pyproject.toml").read_text()


def test_a_bump_within_the_ranges_writes_the_version_and_a_changelog_section(monorepo):
    packages = release.load_packages(monorepo)
    assert str(release.bump(packages, "easynav-core", "patch")) == "0.1.1"
    assert 'version = "0.1.1"' in (monorepo / "easynav-core" / "pyproject.toml").read_text()
    changelog = (monorepo / "easynav-core" / "CHANGELOG.md").read_text()
    assert changelog.index("## 0.1.1") < changelog.index("## 0.1.0")
    assert release.check(release.load_packages(monorepo)) == []


def test_the_lowest_sibling_is_the_range_lower_bound():
    packages = release.load_packages()
    core = packages["easynav-core"]
    req = next(r for r in packages["easynav-planners"].requirements if r.name == "easynav-core")
    assert release.lower_bound(req.specifier) <= core.version
    assert release.commit_with_version(core, core.version) is not None


def test_the_isolated_installs_build_no_package_in_its_source_folder(monkeypatch):
    # The two isolated installs of the suite run at once: building the message package in its
    # own folder twice at the same time collided on its build/ (a CI run failed so).
    built = []

    class Stop(Exception):
        pass

    def record(folder, out, python=sys.executable):
        built.append(folder)
        return []

    def stop_at_the_venv(cmd, **kwargs):
        raise Stop

    monkeypatch.setattr(release, "build_folder", record)
    monkeypatch.setattr(release, "run", stop_at_the_venv)
    monkeypatch.setattr(release, "same_python", lambda a, b: True)
    packages = release.load_packages()
    with pytest.raises(Stop):
        release.isolated(packages, ["easynav-planners"], sys.executable, "highest", [])
    assert "easynav-interfaces" in {folder.name for folder in built}
    assert built and not any(folder.is_relative_to(REPO) for folder in built)


def test_a_source_copy_holds_what_git_lists(tmp_path):
    # What a build in the repository sees: hatchling leaves out what .gitignore names, so the
    # copy does too; an earlier build's build/ and egg-info are ignored.
    import subprocess

    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    (tmp_path / ".gitignore").write_text("build/\ndist/\n*.egg-info/\n__pycache__/\n*.png\n")
    folder = tmp_path / "packages" / "easynav-x"
    for path in ("pyproject.toml", "src/easynav/x/__init__.py", "src/easynav/x/data/map.yaml",
                 "src/easynav/x/picture.png", "build/lib/old.py", "dist/old.whl",
                 "easynav_x.egg-info/PKG-INFO", "src/easynav/x/__pycache__/m.pyc", "gone.py"):
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        (folder / path).write_text("")
    (folder / "src/easynav/x/link.yaml").symlink_to("data/map.yaml")
    subprocess.run(["git", "add", "pyproject.toml", "gone.py"], cwd=folder, check=True)
    (folder / "gone.py").unlink()
    copy = release.source_copy(folder, tmp_path / "copies")
    assert copy == tmp_path / "copies" / "easynav-x"
    assert sorted(str(p.relative_to(copy)) for p in copy.rglob("*") if p.is_file()) == [
        "pyproject.toml", "src/easynav/x/__init__.py", "src/easynav/x/data/map.yaml",
        "src/easynav/x/link.yaml"]
    assert not (copy / "src/easynav/x/link.yaml").is_symlink()
