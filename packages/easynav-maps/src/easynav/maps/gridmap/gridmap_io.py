"""Reading and writing GridMaps: the original's YAML + PGM files and a NumPy ``.npz`` file.

The original (easynav_gridmap_maps_manager ``save_gridmap``/``load_gridmap``) writes
``<dir>/<stem>.yaml``::

    layers:
      - {name: elevation, min: -0.5, max: 2.0}
    resolution: 0.1
    length: [20, 10]        # x, y extent (m)
    position: [0, 0]        # centre of the map (m)

and one 8-bit PGM per layer, ``<dir>/<stem>_<layer>.pgm``, a pixel ``p`` standing for
``min + (max - min) * p / 255``. The image follows grid_map's index order: row ``i`` runs along
-x from the map's +x edge, column ``j`` along -y from its +y edge; here it is turned into the
``[iy, ix]`` order of :class:`GridMap`.

Our ``.npz`` format keeps the heights exactly: arrays ``elevation`` (``[iy, ix]``, m, NaN
unknown), ``resolution`` and ``origin`` (``[x, y]`` of the lower-left corner), and optionally more
float layers named ``layer_<name>``.
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import yaml

from easynav.maps.gridmap.grid_map import ELEVATION, SLOPE, TRAVERSABILITY, GridMap
from easynav.maps.map_format_error import MapFormatError

_DERIVED = (SLOPE, TRAVERSABILITY)


def load_gridmap(path: str | Path, max_slope_rad: float = math.radians(30.0)) -> GridMap:
    """Load a GridMap from the original's ``.yaml`` (+ PGMs) or our ``.npz``.

    The ``slope`` and ``traversability`` layers are derived from ``elevation`` (with
    ``max_slope_rad`` for traversability). Raises :class:`FileNotFoundError` naming a missing
    file and :class:`MapFormatError` naming the file and the key at fault.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"gridmap file not found: {path}")
    if path.suffix == ".npz":
        grid = _load_npz(path)
    elif path.suffix in (".yaml", ".yml"):
        grid = _load_original_yaml(path)
    else:
        raise MapFormatError(f"{path}: unknown gridmap format (expected .yaml or .npz)")
    if ELEVATION not in grid.layers:
        raise MapFormatError(f"{path}: no 'elevation' layer (layers: {sorted(grid.layers)})")
    grid.derive_layers(max_slope_rad)
    return grid


def _load_npz(path: Path) -> GridMap:
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: np.array(data[name]) for name in data.files}
    except (OSError, ValueError) as exc:
        raise MapFormatError(f"{path}: not a readable .npz file: {exc}") from None
    for key in (ELEVATION, "resolution", "origin"):
        if key not in arrays:
            raise MapFormatError(f"{path}: missing array {key!r}")
    elevation = arrays[ELEVATION].astype(float)
    if elevation.ndim != 2 or min(elevation.shape) < 1:
        raise MapFormatError(f"{path}: 'elevation' must be a 2-D array, got {elevation.shape}")
    origin = arrays["origin"].astype(float).ravel()
    if origin.size != 2 or not np.isfinite(origin).all():
        raise MapFormatError(f"{path}: 'origin' must be two finite numbers, got {origin}")
    resolution = float(arrays["resolution"])
    if not (math.isfinite(resolution) and resolution > 0):
        raise MapFormatError(f"{path}: 'resolution' must be > 0, got {resolution}")
    layers = {ELEVATION: elevation}
    for name, array in arrays.items():
        if name.startswith("layer_") and name[6:] not in _DERIVED:
            if array.shape != elevation.shape:
                raise MapFormatError(f"{path}: layer {name!r} has shape {array.shape}, "
                                     f"elevation {elevation.shape}")
            layers[name[6:]] = array.astype(float)
    return GridMap(resolution, float(origin[0]), float(origin[1]), layers)


def _number(path: Path, value: object, key: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise MapFormatError(f"{path}: '{key}' must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise MapFormatError(f"{path}: '{key}' must be finite, got {value!r}")
    return number


def _pair(path: Path, doc: dict, key: str) -> tuple[float, float]:
    value = doc.get(key)
    if not isinstance(value, list) or len(value) != 2:
        raise MapFormatError(f"{path}: '{key}' must be a list of two numbers, got {value!r}")
    return _number(path, value[0], f"{key}[0]"), _number(path, value[1], f"{key}[1]")


def _load_original_yaml(path: Path) -> GridMap:
    try:
        doc = yaml.load(path.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except yaml.YAMLError as exc:
        raise MapFormatError(f"{path}: invalid YAML: {exc}") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("layers"), list):
        raise MapFormatError(f"{path}: not a gridmap file: no 'layers' list")
    resolution = _number(path, doc.get("resolution"), "resolution")
    if resolution <= 0:
        raise MapFormatError(f"{path}: 'resolution' must be > 0, got {resolution}")
    length_x, length_y = _pair(path, doc, "length")
    pos_x, pos_y = _pair(path, doc, "position")
    nx, ny = round(length_x / resolution), round(length_y / resolution)
    if nx < 1 or ny < 1:
        raise MapFormatError(f"{path}: 'length' {length_x} x {length_y} holds no cell")
    layers: dict[str, np.ndarray] = {}
    for i, entry in enumerate(doc["layers"]):
        if not isinstance(entry, dict) or "name" not in entry:
            raise MapFormatError(f"{path}: layers[{i}] must be a mapping with a 'name'")
        name = str(entry["name"])
        low = _number(path, entry.get("min"), f"layers[{i}].min")
        high = _number(path, entry.get("max"), f"layers[{i}].max")
        image_path = path.parent / f"{path.stem}_{name}.pgm"
        if not image_path.is_file():
            raise FileNotFoundError(f"{path}: image of layer {name!r} not found: {image_path}")
        image = cv2.imread(str(image_path), cv2.IMREAD_GRAYSCALE)
        if image is None:
            raise MapFormatError(f"{image_path}: not a readable image (layer {name!r} of {path})")
        if image.shape != (nx, ny):
            raise MapFormatError(
                f"{image_path}: image is {image.shape[0]} rows x {image.shape[1]} columns, the "
                f"map's length / resolution needs {nx} x {ny} (rows along x)"
            )
        values = low + (high - low) * image.astype(float) / 255.0
        # grid_map index (i, j): i along -x, j along -y -> [iy, ix].
        layers[name] = values[::-1, ::-1].T.copy()
    origin_x = pos_x - nx * resolution / 2.0
    origin_y = pos_y - ny * resolution / 2.0
    for name in _DERIVED:
        layers.pop(name, None)  # recomputed from the elevation
    return GridMap(resolution, origin_x, origin_y, layers)


def save_gridmap_npz(grid: GridMap, path: str | Path) -> Path:
    """Write ``grid`` as our ``.npz`` (exact heights; derived layers are not stored)."""
    path = Path(path)
    arrays = {
        ELEVATION: np.asarray(grid.elevation, float),
        "resolution": np.float64(grid.resolution),
        "origin": np.array([grid.origin_x, grid.origin_y]),
    }
    for name, layer in grid.layers.items():
        if name not in (ELEVATION, *_DERIVED):
            arrays[f"layer_{name}"] = np.asarray(layer, float)
    with path.open("wb") as handle:
        np.savez_compressed(handle, **arrays)
    return path


def save_gridmap_yaml(grid: GridMap, path: str | Path) -> Path:
    """Write ``grid``'s non-derived layers in the original's format (8-bit: heights quantised).

    Unknown (NaN) cells are written as the layer's minimum, as an 8-bit image cannot hold them.
    """
    path = Path(path)
    h, w = grid.shape
    entries = []
    for name, layer in grid.layers.items():
        if name in _DERIVED:
            continue
        values = np.asarray(layer, float)
        known = values[np.isfinite(values)]
        low = float(known.min()) if known.size else 0.0
        high = float(known.max()) if known.size else 0.0
        span = high - low if high > low else 1.0
        pixels = np.rint((np.nan_to_num(values, nan=low) - low) / span * 255.0)
        image = pixels.astype(np.uint8).T[::-1, ::-1]  # [iy, ix] -> grid_map (i, j)
        cv2.imwrite(str(path.parent / f"{path.stem}_{name}.pgm"), np.ascontiguousarray(image))
        entries.append({"name": name, "min": low, "max": high})
    doc = {
        "layers": entries,
        "resolution": float(grid.resolution),
        "length": [w * grid.resolution, h * grid.resolution],
        "position": [grid.origin_x + w * grid.resolution / 2.0,
                     grid.origin_y + h * grid.resolution / 2.0],
    }
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path
