"""ROS map_server maps: a YAML file naming an image, its resolution, origin and thresholds.

Pixels are classified exactly as ROS 1 map_server (``map_server/src/image_loader.cpp``) does:

* ``v`` is the mean of the pixel's channels on the 8-bit scale; in ``trinary`` mode (the default) an
  alpha channel is averaged in too (map_server reads grey+alpha as RGBA, so ``v = (3 g + a) / 4``),
  in ``scale`` and ``raw`` mode it is left out;
* ``p = (255 - v) / 255`` is the occupancy probability (``p = v / 255`` when ``negate`` is set);
* occupied where ``p > occupied_thresh``, free where ``p < free_thresh``, unknown otherwise.

For simulation a building must be closed, so only confidently free cells are free: the occupancy
grid is ``not (p < free_thresh)``, unknown counting as wall, in every mode. In ``raw`` mode the pixel
value itself is the occupancy in percent (0 free, 100 occupied, 255 unknown), so a cell is free where
``value / 100 < free_thresh``. A fully transparent pixel (alpha 0) is never free, as in ROS 2's nav2
map_server; ROS 1 agrees for trinary maps whenever ``free_thresh <= 0.25``.

A ``slamtrials:`` block, as written by :func:`slamtrials.worlds.formats.rosmap_save.save_rosmap`, gives
the world's name, start pose and metadata back; map_server ignores it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from slamtrials.errors import FormatError, WorldError
from slamtrials.worlds.formats.image import read_pixels
from slamtrials.worlds.world import World

__all__ = ["load_rosmap", "MAP_MODES", "classify_rosmap"]

#: Values of the optional ``mode`` key that map_server understands.
MAP_MODES = ("trinary", "scale", "raw")
_REQUIRED = ("image", "resolution", "origin")
#: Defaults of map_saver for keys that map_server would insist on; we accept their absence.
_DEFAULTS = {"negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.196}


def _parse(path: Path) -> tuple[Any, dict[str, int], Any]:
    """Read the YAML file: (document, {top-level key: 1-based line}, the root node)."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FormatError(path, "no such map yaml file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise FormatError(path, f"cannot read the map yaml file ({exc})") from exc
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        doc = loader.construct_document(node) if node is not None else None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc)
        raise FormatError(path, f"not valid YAML: {problem}", line=None if mark is None else mark.line + 1) from None
    finally:
        loader.dispose()
    if not isinstance(doc, dict):
        raise FormatError(
            path, "expected a YAML mapping with the map_server keys image, resolution, origin, ...", line=1
        )
    return doc, _key_lines(node), node


def _key_lines(node: Any) -> dict[str, int]:
    if not isinstance(node, yaml.MappingNode):
        return {}
    return {str(k.value): k.start_mark.line + 1 for k, _ in node.value if isinstance(k, yaml.ScalarNode)}


def _sub_lines(node: Any, key: str) -> dict[str, int]:
    if isinstance(node, yaml.MappingNode):
        for k, v in node.value:
            if isinstance(k, yaml.ScalarNode) and k.value == key:
                return _key_lines(v)
    return {}


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


class _Fields:
    """Typed access to the keys of one YAML mapping, raising FormatError that names file, line and key."""

    def __init__(self, path: Path, doc: dict, lines: dict[str, int], prefix: str = ""):
        self.path, self.doc, self.lines, self.prefix = path, doc, lines, prefix

    def fail(self, key: str, problem: str) -> FormatError:
        return FormatError(self.path, f"{self.prefix}{key}: {problem}", line=self.lines.get(key))

    def number(self, key: str) -> float:
        value = self.doc[key]
        if not _is_number(value):
            raise self.fail(key, f"expected a number, got {value!r}")
        return float(value)

    def numbers(self, key: str, counts: tuple[int, ...]) -> list[float]:
        value = self.doc[key]
        if not isinstance(value, list) or len(value) not in counts or not all(_is_number(v) for v in value):
            expected = " or ".join(str(c) for c in counts)
            raise self.fail(key, f"expected a list of {expected} numbers, got {value!r}")
        return [float(v) for v in value]


def classify_rosmap(
    colour: np.ndarray,
    alpha: np.ndarray | None,
    *,
    negate: bool,
    occupied_thresh: float,
    free_thresh: float,
    mode: str = "trinary",
) -> tuple[np.ndarray, np.ndarray]:
    """Classify pixels as map_server does.

    Parameters
    ----------
    colour, alpha:
        ``[H, W, C]`` and ``[H, W]`` (or ``None``) on the 8-bit scale, from :func:`read_pixels`.
    negate, occupied_thresh, free_thresh, mode:
        The map yaml's values.

    Returns
    -------
    free, occupied:
        bool ``[H, W]`` each; cells in neither are unknown.
    """
    mean = colour.mean(axis=2)
    if alpha is not None and mode == "trinary":
        # map_server reads grey+alpha as RGBA and averages all four bytes in trinary mode
        value = (3.0 * mean + alpha) / 4.0
    else:
        value = mean
    if negate:
        value = 255.0 - value
    if mode == "raw":
        free = value / 100.0 < free_thresh
        occupied = (value / 100.0 > occupied_thresh) & (value <= 100.0)
    else:
        occ = (255.0 - value) / 255.0
        free = occ < free_thresh
        occupied = occ > occupied_thresh
    if alpha is not None:
        free &= alpha > 0
    return free, occupied & ~free


def load_rosmap(path: str | Path, *, name: str | None = None) -> World:
    """Load a ROS map_server map (YAML + image) as a :class:`World`.

    Parameters
    ----------
    path:
        The map's YAML file. Its ``image`` is found relative to the YAML file's folder.
    name:
        World name. Defaults to the ``slamtrials.name`` of the YAML, else the file name without suffix
        (the folder's name when the file is the generic ``map.yaml``).

    Returns
    -------
    World
        ``occupied`` ``[H, W]`` is the image's shape, row 0 the top row; ``resolution`` and ``origin``
        (x, y, yaw of the lower-left pixel's corner) are the YAML's. ``metadata`` is the YAML's
        ``slamtrials.metadata`` if any, else ``source``, ``format`` ("rosmap"), ``image``, the thresholds,
        mode and pixel counts.

    Raises
    ------
    FormatError
        Missing keys, values of the wrong type or range (0 <= free_thresh < occupied_thresh <= 1,
        resolution > 0), a missing or unreadable image. The message names the YAML file, the line of
        the key and the key.
    WorldError
        The map has no free cell, or the stored start pose is not in free space.
    """
    path = Path(path)
    doc, lines, root = _parse(path)
    fields = _Fields(path, doc, lines)
    missing = [key for key in _REQUIRED if key not in doc]
    if missing:
        raise FormatError(
            path, f"missing map_server key(s) {', '.join(missing)} (needs image, resolution, origin)", line=1
        )
    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise fields.fail("image", f"expected the image file name, got {image!r}")
    resolution = fields.number("resolution")
    if resolution <= 0:
        raise fields.fail("resolution", f"must be > 0 metres per pixel, got {doc['resolution']!r}")
    origin = fields.numbers("origin", (3, 2))
    values = {**_DEFAULTS, **{k: doc[k] for k in _DEFAULTS if k in doc}}
    negate = values["negate"]
    if negate not in (0, 1) or isinstance(negate, float):
        raise fields.fail("negate", f"expected 0 or 1, got {negate!r}")
    thresholds = {}
    for key in ("occupied_thresh", "free_thresh"):
        if not _is_number(values[key]):
            raise fields.fail(key, f"expected a number between 0 and 1, got {values[key]!r}")
        thresholds[key] = float(values[key])
    occupied_thresh, free_thresh = thresholds["occupied_thresh"], thresholds["free_thresh"]
    if not (0.0 <= free_thresh < occupied_thresh <= 1.0):
        if not 0.0 <= occupied_thresh <= 1.0:
            bad = "occupied_thresh"
        elif not 0.0 <= free_thresh <= 1.0 or "free_thresh" in lines:
            bad = "free_thresh"
        else:
            bad = "occupied_thresh"
        raise fields.fail(
            bad,
            "thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1, "
            f"got free_thresh={free_thresh:g}, occupied_thresh={occupied_thresh:g}",
        )
    mode = doc.get("mode", "trinary")
    if mode not in MAP_MODES:
        raise fields.fail("mode", f"expected one of {', '.join(MAP_MODES)}, got {mode!r}")
    saved = _slamtrials_block(path, doc, lines, root)

    image_path = Path(image).expanduser()
    if not image_path.is_absolute():
        image_path = path.parent / image_path
    if not image_path.is_file():
        raise fields.fail("image", f"image file {image!r} not found (looked for {image_path})")
    try:
        colour, alpha = read_pixels(image_path)
    except FormatError as exc:
        raise FormatError(
            exc.path, f"{exc.problem} (the image of {path.name}:{lines.get('image')})", offset=exc.offset
        ) from exc
    free, occupied = classify_rosmap(
        colour, alpha, negate=bool(negate), occupied_thresh=occupied_thresh, free_thresh=free_thresh, mode=mode
    )
    if not free.any():
        raise WorldError(
            f"{path}: the map has no free space: no pixel of {image} has occupancy p < free_thresh={free_thresh:g} "
            f"(negate={int(bool(negate))}, mode {mode})"
        )
    if "metadata" in saved:
        metadata = dict(saved["metadata"])
        metadata.setdefault("source", str(path))
        metadata.setdefault("format", "rosmap")
    else:
        metadata = {
            "source": str(path),
            "format": "rosmap",
            "image": str(image_path),
            "mode": mode,
            "negate": int(bool(negate)),
            "occupied_thresh": occupied_thresh,
            "free_thresh": free_thresh,
            "occupied_pixels": int(np.count_nonzero(occupied)),
            "unknown_pixels": int(np.count_nonzero(~free & ~occupied)),
        }
    default_name = path.parent.name if path.stem == "map" and path.parent.name else path.stem
    return World(
        occupied=~free,
        resolution=resolution,
        origin=np.array(origin + [0.0] * (3 - len(origin))),
        name=name or saved.get("name") or default_name,
        start=saved.get("start"),
        metadata=metadata,
    )


def _slamtrials_block(path: Path, doc: dict, lines: dict[str, int], root: Any) -> dict[str, Any]:
    """The validated ``slamtrials:`` block: any of name (str), start (array [3]), metadata (dict)."""
    block = doc.get("slamtrials")
    if block is None:
        return {}
    if not isinstance(block, dict):
        raise FormatError(
            path,
            f"slamtrials: expected a mapping with name, start, metadata, got {block!r}",
            line=lines.get("slamtrials"),
        )
    fields = _Fields(path, block, _sub_lines(root, "slamtrials"), prefix="slamtrials.")
    out: dict[str, Any] = {}
    if block.get("name") is not None:
        if not isinstance(block["name"], str):
            raise fields.fail("name", f"expected a string, got {block['name']!r}")
        out["name"] = block["name"]
    if block.get("start") is not None:
        out["start"] = np.array(fields.numbers("start", (3,)))
    if block.get("metadata") is not None:
        if not isinstance(block["metadata"], dict):
            raise fields.fail("metadata", f"expected a mapping, got {block['metadata']!r}")
        out["metadata"] = block["metadata"]
    return out
