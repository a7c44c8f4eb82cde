"""SLAM occupancy maps as ROS map_server files (YAML + trinary PGM or PNG), as ROS 1 map_saver writes them.

A SLAM map here is an occupancy grid ``[H, W]`` with row 0 at the top (the image's orientation, DESIGN.md),
a resolution (m per cell) and an origin (world pose x, y, yaw of the lower-left corner of the lower-left
cell, as in map_server). Its cells are either

* integers (e.g. ``int8`` of a ``nav_msgs/OccupancyGrid``): occupancy in percent 0..100, negative for
  unknown; or
* floats: occupancy probability 0..1, NaN or negative for unknown; or
* booleans: True occupied, False free.

Like map_saver (``map_server/src/map_saver.cpp``), a cell is written **free** (grey 254) when its
occupancy is at most 25 %, **occupied** (grey 0) when at least 65 %, and **unknown** (grey 205)
otherwise, and the YAML says ``occupied_thresh: 0.65``, ``free_thresh: 0.196``, ``negate: 0``, ``mode:
trinary``. map_server reads 254 back as free, 0 as occupied and 205 as unknown, and so do
:func:`read_map` and :func:`slamtrials.worlds.load_world` (which, needing a closed building, counts
unknown as occupied).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import ArrayLike, NDArray

from slamtrials.atomicfile import atomic_write, atomic_write_bytes, atomic_write_text
from slamtrials.errors import FormatError
from slamtrials.io.yamlfile import read_yaml_mapping
from slamtrials.record import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from slamtrials.worlds.formats.image import read_pixels
from slamtrials.worlds.formats.rosmap import MAP_MODES, classify_rosmap

__all__ = [
    "OccupancyGrid",
    "write_map",
    "write_map_png",
    "read_map",
    "trinary",
    "FREE",
    "OCCUPIED",
    "UNKNOWN",
    "FREE_GREY",
    "OCCUPIED_GREY",
    "UNKNOWN_GREY",
]

#: Grey levels map_saver writes.
FREE_GREY, OCCUPIED_GREY, UNKNOWN_GREY = 254, 0, 205
#: map_saver's defaults: at most 25 % is free, at least 65 % occupied.
FREE_MAX_PERCENT, OCCUPIED_MIN_PERCENT = 25.0, 65.0
_YAML_THRESHOLDS = {"occupied_thresh": 0.65, "free_thresh": 0.196}


def trinary(grid: ArrayLike) -> NDArray[np.int8]:
    """Classify an occupancy grid (integer %, float probability or bool; see the module) as 0 / 100 / -1.

    Returns
    -------
    NDArray[np.int8]
        ``[H, W]``: 0 free (occupancy <= 25 %), 100 occupied (>= 65 %), -1 unknown (negative, NaN or in
        between).
    """
    grid = np.asarray(grid)
    if grid.ndim != 2:
        raise ValueError(f"an occupancy grid is 2-D [H, W], got shape {grid.shape}")
    if grid.dtype == np.bool_:
        return np.where(grid, OCCUPIED, FREE).astype(np.int8)
    if np.issubdtype(grid.dtype, np.integer):
        percent = grid.astype(np.float64)
    elif np.issubdtype(grid.dtype, np.floating):
        percent = grid.astype(np.float64) * 100.0
    else:
        raise ValueError(
            f"an occupancy grid holds integers (%), floats (probability) or booleans, got dtype {grid.dtype}"
        )
    out = np.full(grid.shape, UNKNOWN, dtype=np.int8)
    known = np.isfinite(percent) & (percent >= 0.0)
    out[known & (percent <= FREE_MAX_PERCENT)] = FREE
    out[known & (percent >= OCCUPIED_MIN_PERCENT)] = OCCUPIED
    return out


def _grey(grid: ArrayLike) -> NDArray[np.uint8]:
    cells = trinary(grid)
    grey = np.full(cells.shape, UNKNOWN_GREY, dtype=np.uint8)
    grey[cells == FREE] = FREE_GREY
    grey[cells == OCCUPIED] = OCCUPIED_GREY
    return grey


def _check_geometry(resolution: float, origin: ArrayLike) -> tuple[float, list[float]]:
    resolution = float(resolution)
    if not math.isfinite(resolution) or resolution <= 0:
        raise ValueError(f"resolution must be a positive number of metres per cell, got {resolution!r}")
    values = [float(v) for v in np.asarray(origin, dtype=np.float64).reshape(-1)]
    if len(values) == 2:
        values.append(0.0)
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"origin must be (x, y) or (x, y, yaw) in metres and radians, got {origin!r}")
    return resolution, values


def write_map(
    yaml_path: str | Path, grid: ArrayLike, resolution: float, origin: ArrayLike, *, image: str | None = None
) -> Path:
    """Write a SLAM map as map_saver does: a YAML file and a trinary image beside it.

    Parameters
    ----------
    yaml_path:
        The YAML file to write.
    grid:
        ``[H, W]`` occupancy (integer %, float probability or bool; see the module), row 0 at the top.
    resolution:
        Metres per cell.
    origin:
        World pose (x, y[, yaw]) of the lower-left corner of the grid (m, rad).
    image:
        File name of the image, relative to the YAML's folder; ``.pgm`` (binary P5, as map_saver) or
        ``.png``. Default: the YAML's name with ``.pgm``.

    Returns
    -------
    Path
        ``yaml_path``. Both files are written atomically, the image first.
    """
    yaml_path = Path(yaml_path)
    resolution, origin_list = _check_geometry(resolution, origin)
    image = image or yaml_path.with_suffix(".pgm").name
    image_path = yaml_path.parent / image
    grey = _grey(grid)
    if image_path.suffix.lower() == ".pgm":
        header = f"P5\n# CREATOR: slamtrials {resolution:.3f} m/pix\n{grey.shape[1]} {grey.shape[0]}\n255\n".encode(
            "ascii"
        )
        atomic_write_bytes(image_path, header + grey.tobytes())
    elif image_path.suffix.lower() == ".png":
        write_map_png(image_path, grid)
    else:
        raise ValueError(f"image must be a .pgm or .png file name, got {image!r}")
    doc = {
        "image": image,
        "resolution": resolution,
        "origin": origin_list,
        "negate": 0,
        **_YAML_THRESHOLDS,
        "mode": "trinary",
    }
    atomic_write_text(yaml_path, yaml.safe_dump(doc, sort_keys=False, default_flow_style=None))
    return yaml_path


def write_map_png(path: str | Path, grid: ArrayLike) -> Path:
    """Write the trinary picture of a SLAM map (free 254, occupied 0, unknown 205) as an 8-bit grey PNG."""
    from PIL import Image

    grey = _grey(grid)
    return atomic_write(
        Path(path), lambda handle: Image.fromarray(grey, mode="L").save(handle, format="PNG", optimize=True)
    )


def _number(path: Path, doc: dict[str, Any], key: str) -> float:
    value = doc[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise FormatError(path, f"{key}: expected a number, got {value!r}")
    return float(value)


def read_map(yaml_path: str | Path) -> OccupancyGrid:
    """Read a map_server map (YAML + image) as a trinary :class:`OccupancyGrid`.

    Pixels are classified as map_server does (:func:`slamtrials.worlds.formats.rosmap.classify_rosmap`,
    honouring ``negate``, the thresholds and ``mode``), so maps of other tools read as ROS would read
    them.

    Raises
    ------
    FormatError
        The YAML is missing, malformed or lacks ``image``/``resolution``/``origin``, a value has the
        wrong type or range, or the image is missing or unreadable. The message names the file.
    """
    path = Path(yaml_path)
    doc = read_yaml_mapping(path)
    missing = [key for key in ("image", "resolution", "origin") if key not in doc]
    if missing:
        raise FormatError(path, f"missing map_server key(s) {', '.join(missing)}")
    if not isinstance(doc["image"], str) or not doc["image"].strip():
        raise FormatError(path, f"image: expected a file name, got {doc['image']!r}")
    resolution = _number(path, doc, "resolution")
    if resolution <= 0:
        raise FormatError(path, f"resolution: must be > 0 metres per cell, got {resolution!r}")
    origin = doc["origin"]
    if (
        not isinstance(origin, list)
        or len(origin) not in (2, 3)
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in origin)
    ):
        raise FormatError(path, f"origin: expected [x, y, yaw], got {origin!r}")
    settings = {"negate": 0, **_YAML_THRESHOLDS, **{k: doc[k] for k in ("negate", *_YAML_THRESHOLDS) if k in doc}}
    if settings["negate"] not in (0, 1) or isinstance(settings["negate"], float):
        raise FormatError(path, f"negate: expected 0 or 1, got {settings['negate']!r}")
    free_thresh, occupied_thresh = _number(path, settings, "free_thresh"), _number(path, settings, "occupied_thresh")
    if not 0.0 <= free_thresh < occupied_thresh <= 1.0:
        raise FormatError(
            path,
            "thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1, "
            f"got {free_thresh:g}, {occupied_thresh:g}",
        )
    mode = doc.get("mode", "trinary")
    if mode not in MAP_MODES:
        raise FormatError(path, f"mode: expected one of {', '.join(MAP_MODES)}, got {mode!r}")
    image_path = Path(doc["image"]).expanduser()
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    colour, alpha = read_pixels(image_path)
    free, occupied = classify_rosmap(
        colour,
        alpha,
        negate=bool(settings["negate"]),
        occupied_thresh=occupied_thresh,
        free_thresh=free_thresh,
        mode=mode,
    )
    grid = np.full(free.shape, UNKNOWN, dtype=np.int8)
    grid[free] = FREE
    grid[occupied] = OCCUPIED
    values = [float(v) for v in origin] + [0.0] * (3 - len(origin))
    return OccupancyGrid(grid=grid, resolution=resolution, origin=np.array(values))
