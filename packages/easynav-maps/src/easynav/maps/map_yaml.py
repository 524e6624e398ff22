"""Loading ROS map_server maps (a YAML file and a PGM/PNG image) as occupancy grids.

map_server semantics (ROS 1 map_server / Nav2 map_io):

- YAML keys: ``image`` (path, relative to the YAML's folder unless absolute), ``resolution``
  (m/pixel), ``origin`` ``[x, y, yaw]`` (pose of the lower-left pixel), ``occupied_thresh``,
  ``free_thresh`` (required), ``negate`` (0), ``mode`` (``trinary``, ``scale`` or ``raw``).
- The pixel shade is the mean of its colour channels (alpha excluded) scaled to 0…1 (white = 1).
  ``occ = 1 - shade`` (``shade`` when ``negate``).
- trinary: ``occ > occupied_thresh`` → 100, ``occ < free_thresh`` → 0, else -1.
- scale: as trinary, but a pixel that is not fully opaque is -1 and values in between map
  linearly to 1…99 (``round(99 (occ - free) / (occupied - free))``).
- raw: the grey value (0…255) itself when it is 0…100, else -1 (Nav2's rule).
- The image's top row is the map's last row (y grows upwards in the map).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from easynav.core.types import Header, Pose
from easynav.maps.map_format_error import MapFormatError
from easynav.maps.occupancy_grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid

MODES = ("trinary", "scale", "raw")
#: Every key a map YAML may hold; any other is a typo (``occupied_threshold``) and refused.
KNOWN_KEYS = ("image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode")
#: Pixel values map_saver writes in trinary mode, and the thresholds that read them back.
SAVED_FREE_PIXEL = 254
SAVED_UNKNOWN_PIXEL = 205
SAVED_OCCUPIED_PIXEL = 0
SAVED_OCCUPIED_THRESH = 0.65
SAVED_FREE_THRESH = 0.196


def _number(doc: dict[str, Any], key: str, source: Path, default: Any = None) -> float:
    if key not in doc:
        if default is None:
            raise MapFormatError(f"{source}: required key '{key}' is missing")
        return float(default)
    value = doc[key]
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise MapFormatError(f"{source}: '{key}' must be a number, got {value!r}")
    if not math.isfinite(value):
        raise MapFormatError(f"{source}: '{key}' must be finite, got {value!r}")
    return float(value)


def read_map_yaml(path: str | os.PathLike) -> dict[str, Any]:
    """The validated contents of a map YAML: image path (resolved), numbers and mode.

    Raises :class:`FileNotFoundError` or :class:`MapFormatError` naming the file and key.
    """
    source = Path(path)
    if not source.is_file():
        raise FileNotFoundError(f"map YAML not found: {source}")
    try:
        doc = yaml.safe_load(source.read_text())
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise MapFormatError(f"{source}: not valid YAML ({exc})") from None
    if not isinstance(doc, dict):
        raise MapFormatError(f"{source}: expected a mapping of keys (image, resolution, ...)")
    unknown = sorted(str(k) for k in doc if k not in KNOWN_KEYS)
    if unknown:
        raise MapFormatError(
            f"{source}: unknown key(s) {', '.join(repr(k) for k in unknown)}; a map YAML has "
            f"{', '.join(KNOWN_KEYS)}"
        )
    image = doc.get("image")
    if not isinstance(image, str) or not image:
        raise MapFormatError(f"{source}: required key 'image' is missing or not a file name")
    resolution = _number(doc, "resolution", source)
    if resolution <= 0.0:
        raise MapFormatError(f"{source}: 'resolution' must be > 0, got {resolution}")
    origin = doc.get("origin")
    if (
        not isinstance(origin, list | tuple)
        or len(origin) != 3
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in origin)
        or not all(math.isfinite(v) for v in origin)
    ):
        raise MapFormatError(f"{source}: 'origin' must be [x, y, yaw] (finite), got {origin!r}")
    occupied = _number(doc, "occupied_thresh", source)
    free = _number(doc, "free_thresh", source)
    if not 0.0 <= free <= occupied <= 1.0:
        raise MapFormatError(
            f"{source}: thresholds must satisfy 0 <= free_thresh ({free}) <= occupied_thresh "
            f"({occupied}) <= 1"
        )
    negate = doc.get("negate", 0)
    if negate not in (0, 1, True, False):
        raise MapFormatError(f"{source}: 'negate' must be 0 or 1, got {negate!r}")
    mode = str(doc.get("mode", "trinary")).lower()
    if mode not in MODES:
        raise MapFormatError(f"{source}: 'mode' must be one of {', '.join(MODES)}, got {mode!r}")
    image_path = Path(image)
    if not image_path.is_absolute():
        image_path = source.parent / image_path
    return {
        "image": image_path,
        "resolution": resolution,
        "origin": tuple(float(v) for v in origin),
        "occupied_thresh": occupied,
        "free_thresh": free,
        "negate": bool(negate),
        "mode": mode,
    }


def image_to_occupancy(
    image: np.ndarray, mode: str, occupied_thresh: float, free_thresh: float, negate: bool
) -> np.ndarray:
    """Occupancy values (int8, image orientation: row 0 is the top) of a map image.

    ``image``: ``(H, W)`` grey, ``(H, W, 3)`` colour or ``(H, W, 4)`` colour + alpha, uint8 or
    uint16 (as OpenCV reads it). Raises :class:`ValueError` for another layout or mode.
    """
    if mode not in MODES:
        raise ValueError(f"map mode {mode!r} is not one of {', '.join(MODES)}")
    if image.dtype == np.uint8:
        full_scale = 255.0
    elif image.dtype == np.uint16:
        full_scale = 65535.0
    else:
        raise ValueError(f"map image must be 8 or 16 bit, got {image.dtype}")
    alpha = None
    if image.ndim == 2:
        grey = image.astype(np.float64)
    elif image.ndim == 3 and image.shape[2] in (1, 3, 4):
        channels = image.shape[2]
        colour = image[:, :, : 3 if channels >= 3 else 1].astype(np.float64)
        grey = colour.mean(axis=2)
        if channels == 4:
            alpha = image[:, :, 3]
    else:
        raise ValueError(f"map image has an unsupported shape {image.shape}")
    shade = grey / full_scale
    if mode == "raw":
        value = np.rint(shade * 255.0)
        return np.where((value >= FREE) & (value <= OCCUPIED), value, UNKNOWN).astype(np.int8)
    occ = shade if negate else 1.0 - shade
    result = np.full(shade.shape, UNKNOWN, dtype=np.int8)
    if mode == "scale":
        span = occupied_thresh - free_thresh
        if span > 0.0:
            between = np.rint(99.0 * (occ - free_thresh) / span)
            result = np.clip(between, 1, 99).astype(np.int8)
    result[occ > occupied_thresh] = OCCUPIED
    result[occ < free_thresh] = FREE
    if mode == "scale" and alpha is not None:
        result[alpha < np.iinfo(alpha.dtype).max] = UNKNOWN
    return result


_PGM_SPACE = b" \t\n\v\f\r"


def read_pgm(path: str | os.PathLike) -> np.ndarray | None:
    """The pixels of a binary 8-bit PGM (``P5``, maxval 255, the format map_saver writes) as
    OpenCV's ``imread(IMREAD_UNCHANGED)`` gives them: ``(height, width)`` uint8, top row
    first. None for any other file (another format or depth, a short file): OpenCV reads
    those. A process that loads only such maps does not load OpenCV (about 20 MB resident).
    """
    raw = Path(path).read_bytes()
    if raw[:2] != b"P5":
        return None
    fields: list[int] = []
    i, n = 2, len(raw)
    while len(fields) < 3:
        while i < n and raw[i] in _PGM_SPACE:
            i += 1
        if i < n and raw[i] == ord("#"):  # a comment runs to the end of its line
            while i < n and raw[i] not in b"\r\n":
                i += 1
            continue
        start = i
        while i < n and 48 <= raw[i] <= 57:
            i += 1
        if i == start:
            return None
        fields.append(int(raw[start:i]))
    if i >= n or raw[i] not in _PGM_SPACE:
        return None
    width, height, maxval = fields
    start = i + 1  # one whitespace character ends the header
    if maxval != 255 or width < 1 or height < 1 or n - start < width * height:
        return None
    return np.frombuffer(raw, np.uint8, width * height, start).reshape(height, width).copy()


def load_map_yaml(path: str | os.PathLike, frame_id: str = "map") -> OccupancyGrid:
    """Load a ROS map_server map (YAML + image, read with OpenCV, an 8-bit binary PGM with
    :func:`read_pgm`) as an :class:`OccupancyGrid`.

    Raises :class:`FileNotFoundError` (YAML or image missing, naming it) or
    :class:`MapFormatError` (bad key, unreadable image), naming the file.
    """
    info = read_map_yaml(path)
    image_path: Path = info["image"]
    if not image_path.is_file():
        raise FileNotFoundError(f"map image not found: {image_path} (named by {path})")
    image = read_pgm(image_path)
    if image is None:
        import cv2  # here: the usual 8-bit PGM maps are read without OpenCV (issue #21)

        image = cv2.imread(str(image_path), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise MapFormatError(f"{image_path}: OpenCV cannot read this image (named by {path})")
    # OpenCV orders channels BGR(A): the mean of the colours does not care, alpha stays last.
    try:
        occupancy = image_to_occupancy(
            image, info["mode"], info["occupied_thresh"], info["free_thresh"], info["negate"]
        )
    except ValueError as exc:
        raise MapFormatError(f"{image_path}: {exc}") from None
    x, y, yaw = info["origin"]
    return OccupancyGrid(
        header=Header(stamp=0.0, frame_id=frame_id),
        resolution=info["resolution"],
        origin=Pose.from_xy_yaw(x, y, yaw),
        data=np.ascontiguousarray(occupancy[::-1]),
    )


def occupancy_to_trinary_image(
    data: np.ndarray, free_thresh: float = 0.25, occupied_thresh: float = 0.65
) -> np.ndarray:
    """The trinary PGM pixels (uint8, image orientation) map_saver writes for occupancy values.

    ``data[y, x]`` int8 in map orientation (row 0 at the bottom). A value ``<= free_thresh·100``
    (rounded) is free (254), one ``>= occupied_thresh·100`` occupied (0), anything else, -1 and
    values outside 0…100 included, unknown (205): the original's and Nav2's rule.
    """
    values = np.asarray(data, dtype=np.int16)
    free_int = int(np.rint(free_thresh * 100.0))
    occupied_int = int(np.rint(occupied_thresh * 100.0))
    valid = (values >= 0) & (values <= 100)
    pixels = np.full(values.shape, SAVED_UNKNOWN_PIXEL, dtype=np.uint8)
    pixels[valid & (values <= free_int)] = SAVED_FREE_PIXEL
    pixels[valid & (values >= occupied_int)] = SAVED_OCCUPIED_PIXEL
    return np.ascontiguousarray(pixels[::-1])


def save_map_yaml(
    grid: OccupancyGrid,
    path: str | os.PathLike,
    free_thresh: float = 0.25,
    occupied_thresh: float = 0.65,
) -> tuple[Path, Path]:
    """Write ``grid`` as a map_server map: a trinary PGM and the YAML that reads it back.

    ``path`` is the YAML file; the image is written beside it with the same stem and ``.pgm``.
    The YAML names the image by its file name and carries the thresholds that separate the three
    pixel values (0.65 / 0.196, as map_saver writes), so loading gives back the trinary grid.
    Returns ``(yaml_path, image_path)``. Raises :class:`OSError` (naming the file) when a file
    cannot be written, :class:`ValueError` for thresholds outside ``0 <= free < occupied <= 1``.
    """
    if not 0.0 <= free_thresh < occupied_thresh <= 1.0:
        raise ValueError(
            f"save thresholds must satisfy 0 <= free ({free_thresh}) < occupied "
            f"({occupied_thresh}) <= 1"
        )
    yaml_path = Path(path)
    image_path = yaml_path.with_suffix(".pgm")
    pixels = occupancy_to_trinary_image(grid.data, free_thresh, occupied_thresh)
    yaml_path.parent.mkdir(parents=True, exist_ok=True)
    import cv2

    if not cv2.imwrite(str(image_path), pixels):
        raise OSError(f"cannot write map image {image_path}")
    doc = {
        "image": image_path.name,
        "mode": "trinary",
        "resolution": float(grid.resolution),
        "origin": [float(grid.origin.x), float(grid.origin.y), float(grid.origin.yaw)],
        "negate": 0,
        "occupied_thresh": SAVED_OCCUPIED_THRESH,
        "free_thresh": SAVED_FREE_THRESH,
    }
    yaml_path.write_text(yaml.safe_dump(doc, sort_keys=False, default_flow_style=None))
    return yaml_path, image_path
