"""Build the ROS 2 message packages of easynav-interfaces with CMake.

The metadata lives in pyproject.toml; this file only adds the build step.

``build_ext`` configures, builds and installs each CMake project under ``ros/``
(``tf2_msgs``, ``vision_msgs``, ``easynav_interfaces``, in that order) with Ninja
into one temporary prefix, against the ROS 2 Jazzy wheels of the build
environment. The result is shipped in the wheel:

* the generated Python packages (``<prefix>/lib/pythonX.Y/site-packages/*``) as
  ordinary platform-specific packages, without the ``*.egg-info`` that the ament
  Python install writes there;
* everything else (``lib/*.so``, ``share/``, ``include/``) as wheel data files,
  which pip installs at the environment root (``sys.prefix``), where the ROS
  wheels put theirs and where ``ament_index`` and the ROS libraries find them.

See README.md ("How the build works") for the details and the traps.
"""

from __future__ import annotations

import atexit
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROS_SOURCE_DIR = HERE / "ros"
# Dependency order: a package may use the ones built before it (the temporary
# prefix is searched first).
ROS_PACKAGES = ("tf2_msgs", "vision_msgs", "easynav_interfaces")
MIN_CMAKE = (3, 22)
# Set to keep the CMake build trees and the temporary prefix for inspection.
KEEP_ENV = "EASYNAV_INTERFACES_KEEP_BUILD"


def _log(message: str) -> None:
    print(f"easynav-interfaces: {message}", flush=True)


def _site_packages_prefix(entry: str) -> Path | None:
    """``/x/lib/python3.11/site-packages`` -> ``/x``; None for anything else."""
    path = Path(entry)
    if path.name not in ("site-packages", "dist-packages"):
        return None
    if not path.parent.name.startswith("python"):
        return None
    if path.parent.parent.name not in ("lib", "lib64"):
        return None
    return path.parent.parent.parent


def ros_prefixes() -> list[Path]:
    """The prefixes that hold ROS packages (a ``share/ament_index``), best first.

    Under build isolation pip installs the build requirements into an overlay
    prefix whose site-packages is on ``sys.path`` (the ROS wheels put their CMake
    files in ``<overlay>/share``); without isolation they are in ``sys.prefix``.
    Both are searched: the overlay first, then the environment itself.
    """
    candidates = [_site_packages_prefix(entry) for entry in sys.path]
    candidates.append(Path(sys.prefix))
    prefixes: list[Path] = []
    for candidate in candidates:
        if candidate is None:
            continue
        candidate = candidate.resolve()
        if (candidate / "share" / "ament_index").is_dir() and candidate not in prefixes:
            prefixes.append(candidate)
    return prefixes


def _find_tool(module_name: str, attribute: str, program: str) -> str:
    """A tool from its PyPI wheel (cmake, ninja) if importable, else from PATH."""
    try:
        module = __import__(module_name)
        candidate = Path(getattr(module, attribute)) / program
        if candidate.is_file():
            return str(candidate)
    except (ImportError, AttributeError):
        pass
    found = shutil.which(program)
    if found is None:
        raise RuntimeError(
            f"{program} not found: install the build requirements "
            "(pip install -r packages/easynav-interfaces/tools/build_requirements.txt)"
        )
    return found


def _cmake_version(cmake: str) -> tuple[int, ...]:
    first_line = subprocess.run(
        [cmake, "--version"], check=True, capture_output=True, text=True
    ).stdout.splitlines()[0]
    numbers = first_line.split()[-1].split("-")[0].split(".")
    return tuple(int(n) for n in numbers[:2] if n.isdigit())


def _prepend(env: dict[str, str], name: str, entries: list[str]) -> None:
    old = [e for e in env.get(name, "").split(os.pathsep) if e]
    env[name] = os.pathsep.join(entries + [e for e in old if e not in entries])


class BinaryDistribution(Distribution):
    """A platform wheel (it holds compiled code) without setuptools extensions."""

    def has_ext_modules(self) -> bool:
        return True

    def has_data(self) -> bool:
        # setuptools' editable_wheel installs data files only if the distribution
        # has a method of this name (distutils calls it has_data_files).
        return self.has_data_files()


class CMakeBuild(build_ext):
    """Build the message packages with CMake + Ninja instead of compiling extensions."""

    def run(self) -> None:
        started = time.monotonic()
        prefixes = ros_prefixes()
        if not any((p / "share" / "rosidl_default_generators").is_dir() for p in prefixes):
            raise RuntimeError(
                "rosidl_default_generators not found in "
                f"{[str(p) for p in prefixes] or [sys.prefix]}: install the build requirements "
                "first (pip install -r packages/easynav-interfaces/tools/build_requirements.txt) "
                "or build with build isolation"
            )
        cmake = _find_tool("cmake", "CMAKE_BIN_DIR", "cmake")
        ninja = _find_tool("ninja", "BIN_DIR", "ninja")
        version = _cmake_version(cmake)
        if version < MIN_CMAKE:
            raise RuntimeError(f"CMake >= 3.22 needed, {cmake} is {version}")

        work = Path(tempfile.mkdtemp(prefix="easynav-interfaces-build-"))
        if os.environ.get(KEEP_ENV):
            _log(f"keeping the build directory {work}")
        else:
            atexit.register(shutil.rmtree, work, ignore_errors=True)
        stage = work / "prefix"
        stage.mkdir()

        search = [str(stage)] + [str(p) for p in prefixes]
        env = dict(os.environ)
        # Replace, not extend: a sourced ROS installation (/opt/ros/...) must not
        # be mixed with the wheels.
        env["AMENT_PREFIX_PATH"] = os.pathsep.join(search)
        env["CMAKE_PREFIX_PATH"] = os.pathsep.join(search)
        _prepend(env, "PATH", [str(p / "bin") for p in prefixes] + [str(Path(cmake).parent)])
        _prepend(env, "LD_LIBRARY_PATH", [str(p / "lib") for p in prefixes])
        # The LD_LIBRARY_PATH above is what ros_wheels_bootstrapper would set by
        # re-executing every Python process CMake starts; spare it the re-exec.
        env["_ROS_WHEELS_BOOTSTRAP_COMPLETE"] = "1"
        _log(f"ROS prefixes: {', '.join(search[1:])}; cmake {cmake}; ninja {ninja}")

        jobs = self.parallel if isinstance(self.parallel, int) and self.parallel > 0 else None
        for package in ROS_PACKAGES:
            self._build_package(package, cmake, ninja, work, stage, env, jobs)

        self._collect(stage)
        _log(f"built {', '.join(ROS_PACKAGES)} in {time.monotonic() - started:.1f} s")

    def _build_package(
        self,
        package: str,
        cmake: str,
        ninja: str,
        work: Path,
        stage: Path,
        env: dict[str, str],
        jobs: int | None,
    ) -> None:
        started = time.monotonic()
        build_dir = work / "build" / package
        configure = [
            cmake,
            "-S",
            str(ROS_SOURCE_DIR / package),
            "-B",
            str(build_dir),
            "-G",
            "Ninja",
            f"-DCMAKE_MAKE_PROGRAM={ninja}",
            f"-DCMAKE_INSTALL_PREFIX={stage}",
            "-DCMAKE_BUILD_TYPE=Release",
            "-DBUILD_TESTING=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
            f"-DPYTHON_EXECUTABLE={sys.executable}",
        ]
        build = [cmake, "--build", str(build_dir)]
        if jobs:
            build += ["--parallel", str(jobs)]
        for command in (configure, build, [cmake, "--install", str(build_dir)]):
            _log(" ".join(command))
            subprocess.run(command, check=True, env=env)
        _log(f"{package}: {time.monotonic() - started:.1f} s")

    def _collect(self, stage: Path) -> None:
        """Python packages into build_lib, everything else into data_files.

        An editable install (pip install -e) has no build_lib in its wheel: there
        the Python packages go into the data files too, at the same place under
        the environment root (generated code has nothing to edit anyway).
        """
        site_dirs = sorted(
            p for p in stage.glob("lib*/python*/*-packages") if _site_packages_prefix(str(p))
        )
        if not site_dirs:
            raise RuntimeError(f"no Python packages were installed into {stage}")
        for site_dir in site_dirs:
            for metadata in [*site_dir.glob("*.egg-info"), *site_dir.glob("*.dist-info")]:
                # The ament Python install's metadata: the wheel has its own, and
                # two metadata directories for one distribution confuse pip.
                shutil.rmtree(metadata)
        editable = bool(getattr(self, "editable_mode", False))
        build_lib = Path(self.build_lib)
        for site_dir in [] if editable else site_dirs:
            for entry in sorted(site_dir.iterdir()):
                target = build_lib / entry.name
                if target.is_dir():
                    shutil.rmtree(target)
                elif target.exists():
                    target.unlink()
                if entry.is_dir():
                    shutil.copytree(
                        entry, target, ignore=shutil.ignore_patterns("__pycache__", "*.c")
                    )
                else:
                    shutil.copy2(entry, target)

        # The prefix the packages were found in at build time means nothing once
        # the files are at the environment root: record no parent prefix.
        parents = stage / "share" / "ament_index" / "resource_index" / "parent_prefix_path"
        for resource in parents.glob("*"):
            resource.write_text("")

        data: dict[str, list[str]] = {}
        for path in sorted(stage.rglob("*")):
            if path.is_dir() or "__pycache__" in path.parts:
                continue
            in_site_packages = any(path.is_relative_to(s) for s in site_dirs)
            if in_site_packages and (not editable or path.suffix == ".c"):
                continue
            directory = path.parent.relative_to(stage).as_posix()
            data.setdefault(directory, []).append(str(path))
        self.distribution.data_files = sorted(data.items())
        count = sum(len(files) for files in data.values())
        where = "the data files" if editable else build_lib
        _log(f"{count} data files for the environment root, Python packages into {where}")

    def get_outputs(self) -> list[str]:
        return []


setup(distclass=BinaryDistribution, cmdclass={"build_ext": CMakeBuild})
