"""Finding a map file from ``package`` + ``map_path_file`` (the original's parameters).

The original looked the package up with ament_index (``share/<package>/<map_path_file>``).
Here a map is data of an installed Python distribution, found in this order (the first existing
file wins):

1. Entry point group ``easynav.map_packages``: a distribution declares
   ``<package name> = "<python.package>"`` and ships its maps as package data inside that Python
   package, e.g. easynav-maps declares ``easynav_maps = "easynav.maps"`` and ships
   ``easynav/maps/worlds/home.map``: ``package: easynav_maps``,
   ``map_path_file: worlds/home.map``. This is how a distribution whose ROS-style package name
   is not an importable module (``easynav_playground_kobuki``) ships maps.
2. An importable Python package of that name (``package: easynav.maps`` works directly).
3. ROS-style data files: ``<prefix>/share/<package>/<map_path_file>`` for the environment's
   prefix and every ``AMENT_PREFIX_PATH`` entry (a wheel can install them as data files).
4. A file of the distribution of that name (its RECORD) whose path ends with ``map_path_file``.

Names are tried as given and with ``-`` and ``_`` swapped. With ``package`` empty,
``map_path_file`` is a plain path (absolute, or relative to the working directory).
"""

from __future__ import annotations

import importlib.util
import os
import sys
from importlib import metadata, resources
from pathlib import Path, PurePosixPath

ENTRY_POINT_GROUP = "easynav.map_packages"


def _name_variants(name: str) -> list[str]:
    return list(dict.fromkeys((name, name.replace("-", "_"), name.replace("_", "-"))))


def _python_package_dir(module: str) -> Path | None:
    try:
        spec = importlib.util.find_spec(module)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    try:
        root = resources.files(module)
    except (ImportError, TypeError):
        return None
    return Path(str(root))


def _prefixes() -> list[Path]:
    prefixes = [Path(sys.prefix)]
    for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if entry:
            prefixes.append(Path(entry))
    return list(dict.fromkeys(prefixes))


def resolve_map_file(package: str, map_path_file: str) -> Path:
    """The path of the map file named by ``package`` and ``map_path_file``.

    Raises :class:`FileNotFoundError` naming the file and every place that was searched, or
    :class:`ValueError` when ``map_path_file`` is empty.
    """
    if not map_path_file:
        raise ValueError("map_path_file is empty: name the map file to load")
    if not package:
        path = Path(map_path_file).expanduser()
        if path.is_file():
            return path.resolve()
        raise FileNotFoundError(
            f"map file not found: {map_path_file} (package is empty, so map_path_file is a "
            f"path; working directory {Path.cwd()})"
        )
    relative = PurePosixPath(map_path_file)
    if relative.is_absolute() or ".." in relative.parts:
        raise ValueError(
            f"map_path_file {map_path_file!r} must be a relative path inside package "
            f"{package!r} (leave package empty to give a path)"
        )
    tried: list[str] = []
    variants = _name_variants(package)

    # 1. Entry points declared by distributions that ship maps.
    for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in variants:
            module = ep.value.split(":")[0].strip()
            root = _python_package_dir(module)
            candidate = root / relative if root else None
            tried.append(f"entry point {ENTRY_POINT_GROUP}:{ep.name} -> {candidate or module}")
            if candidate is not None and candidate.is_file():
                return candidate

    # 2. An importable Python package of that name.
    for name in variants:
        root = _python_package_dir(name)
        if root is not None:
            candidate = root / relative
            tried.append(str(candidate))
            if candidate.is_file():
                return candidate

    # 3. share/<package>/ under the environment prefix and AMENT_PREFIX_PATH.
    for prefix in _prefixes():
        for name in variants:
            candidate = prefix / "share" / name / relative
            tried.append(str(candidate))
            if candidate.is_file():
                return candidate

    # 4. A file recorded by the distribution of that name.
    for name in variants:
        try:
            dist = metadata.distribution(name)
        except metadata.PackageNotFoundError:
            continue
        for file in dist.files or ():
            parts = PurePosixPath(str(file)).parts
            if parts[-len(relative.parts) :] == relative.parts:
                candidate = Path(str(dist.locate_file(file)))
                if candidate.is_file():
                    return candidate
        tried.append(f"files of distribution {name}")

    raise FileNotFoundError(
        f"map file {map_path_file!r} of package {package!r} not found; searched: "
        + "; ".join(tried)
    )
