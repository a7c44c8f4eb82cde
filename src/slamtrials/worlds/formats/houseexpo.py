"""HouseExpo layouts: a JSON file whose ``verts`` are the free-space contour of a house, in metres.

HouseExpo (Li et al., 2019) stores one house per file::

    {"id": "...", "room_num": 5, "bbox": {"min": [x, y], "max": [x, y]},
     "verts": [[x, y], ...], "room_category": {"kitchen": [[x0, y0, x1, y1]], ...}}

``verts`` is one polygon in metres (y up) that runs around the free space, walls on its outside;
interior walls appear as narrow notches of the polygon. The loader rasterizes it with Pillow: cells
inside the polygon are free, the cells the polygon's outline passes through are wall (one cell thick,
so notches narrower than a cell still block), everything outside is wall. The free region therefore
ends about half a cell inside each edge. The grid covers the polygon's extent plus a margin of wall
cells on every side.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from slamtrials.errors import FormatError
from slamtrials.worlds.formats.image import check_resolution
from slamtrials.worlds.world import World

__all__ = ["load_houseexpo", "HOUSEEXPO_RESOLUTION", "MARGIN_CELLS"]

#: Resolution (m/px) HouseExpo's own tools render at.
HOUSEEXPO_RESOLUTION = 0.05
#: Wall cells added around the polygon's bounding box on each side.
MARGIN_CELLS = 2


def _line_of(text: str, key: str) -> int | None:
    """1-based line of the first ``"key"`` in the JSON text, for error messages."""
    index = text.find(f'"{key}"')
    return None if index < 0 else text.count("\n", 0, index) + 1


def _vertices(path: Path, doc: Any, text: str) -> np.ndarray:
    line = _line_of(text, "verts")
    if not isinstance(doc, dict):
        raise FormatError(path, "expected a JSON object with a 'verts' field (HouseExpo layout)", line=1)
    if "verts" not in doc:
        raise FormatError(
            path, "no 'verts' field: a HouseExpo layout needs the wall polygon [[x, y], ...] in metres", line=1
        )
    raw = doc["verts"]
    if not isinstance(raw, list) or not raw:
        raise FormatError(path, f"verts: expected a non-empty list of [x, y] points, got {raw!r:.60}", line=line)
    ok = all(
        isinstance(p, (list, tuple))
        and len(p) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in p)
        for p in raw
    )
    if not ok:
        raise FormatError(path, "verts: every vertex must be a pair of finite numbers [x, y] in metres", line=line)
    verts = np.asarray(raw, dtype=np.float64)
    if len(verts) > 1 and np.all(verts[0] == verts[-1]):
        verts = verts[:-1]  # closed ring written with the first point repeated
    if len(verts) < 3:
        raise FormatError(path, f"verts: a polygon needs at least 3 distinct vertices, got {len(verts)}", line=line)
    x, y = verts[:, 0], verts[:, 1]
    area = 0.5 * abs(float(np.sum(x * np.roll(y, -1)) - np.sum(y * np.roll(x, -1))))
    if area <= 0.0 or not math.isfinite(area):
        raise FormatError(path, "verts: the polygon has no area (collinear or repeated points)", line=line)
    return verts


def load_houseexpo(
    path: str | Path,
    *,
    resolution: float = HOUSEEXPO_RESOLUTION,
    name: str | None = None,
) -> World:
    """Load a HouseExpo JSON layout as a :class:`World`.

    Parameters
    ----------
    path:
        The layout's ``.json`` file.
    resolution:
        Cell size in metres (default 0.05, HouseExpo's own).
    name:
        World name; defaults to the layout's ``id``, else the file name without suffix.

    Returns
    -------
    World
        Grid ``[H, W]`` covering the polygon plus :data:`MARGIN_CELLS` wall cells on each side, in the
        layout's own frame (metres, y up): ``origin`` is the grid's lower-left corner, theta 0.
        ``metadata`` holds ``source``, ``format`` ("houseexpo"), ``id``, ``room_num`` and the room
        categories when present.

    Raises
    ------
    FormatError
        Not JSON (with the line of the error), no ``verts``, non-numeric vertices, fewer than three
        vertices, a polygon without area, or a polygon without a free cell at this resolution.
    WorldError
        Bad resolution.
    """
    path = Path(path)
    res = check_resolution(resolution, path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FormatError(path, "no such HouseExpo file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise FormatError(path, f"cannot read the file ({exc})") from exc
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"not valid JSON: {exc.msg} (column {exc.colno})", line=exc.lineno) from None
    verts = _vertices(path, doc, text)

    # Half a cell more than the margin, so that edges on the bounding box run through cell centres and
    # their wall cells straddle the edge.
    low = verts.min(axis=0) - (MARGIN_CELLS + 0.5) * res
    extent = verts.max(axis=0) - verts.min(axis=0)
    width, height = (np.ceil(extent / res - 1e-9).astype(int) + 1 + 2 * MARGIN_CELLS).tolist()
    # Pillow puts a point (u, v) in pixel (floor(u), floor(v)), rows growing downwards, so these are
    # the coordinates in cells of the grid's top-left corner; the outline lands on the cells the
    # polygon's edges pass through.
    px = (verts[:, 0] - low[0]) / res
    py = height - (verts[:, 1] - low[1]) / res
    canvas = Image.new("L", (width, height), 0)
    draw = ImageDraw.Draw(canvas)
    points = list(zip(px.tolist(), py.tolist()))
    draw.polygon(points, fill=1)
    draw.line(points + points[:1], fill=0, width=1)
    free = np.asarray(canvas, dtype=bool)
    if not free.any():
        raise FormatError(
            path, f"verts: the polygon has no free cell at resolution {res:g} m", line=_line_of(text, "verts")
        )

    metadata: dict[str, Any] = {"source": str(path), "format": "houseexpo"}
    for key in ("id", "room_num"):
        if isinstance(doc.get(key), (str, int)) and not isinstance(doc.get(key), bool):
            metadata[key] = doc[key]
    if isinstance(doc.get("room_category"), dict):
        metadata["room_category"] = {str(k): v for k, v in doc["room_category"].items()}
    layout_id = doc.get("id")
    return World(
        occupied=~free,
        resolution=res,
        origin=np.array([low[0], low[1], 0.0]),
        name=name or (layout_id if isinstance(layout_id, str) and layout_id else path.stem),
        metadata=metadata,
    )
