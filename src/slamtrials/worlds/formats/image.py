"""Bare floor-plan images (PNG, PGM, anything Pillow reads) with a stated resolution.

A floor-plan image only says where it is dark and where it is bright; which is which is a convention.
This loader uses the one of hand-drawn plans and of ROS maps alike, and is strict about free space:

* every pixel is reduced to a grey level ``g`` in [0, 1] (0 black, 1 white): the mean of the colour
  channels, 8- and 16-bit images alike; palette images go through their palette;
* **free** where ``g >= free_level`` (default 0.9, i.e. 230 of 255 and brighter);
* **wall** where ``g < threshold`` (default 0.5, darker than 128 of 255);
* **unknown** in between, e.g. the grey 205 that ROS map_saver writes for unexplored cells, and every
  fully transparent pixel (alpha 0) whatever its colour.

The simulator needs a closed building, so unknown counts as wall: the occupancy grid is simply
``g < free_level``. ``threshold`` only separates walls from unknown in the statistics kept in
``World.metadata``; it can never turn a pixel free. ``negate=True`` swaps black and white first.

The helpers :func:`read_pixels` and :func:`grey_levels` are shared with the ROS map and Stage loaders.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from PIL import Image

from slamtrials.errors import FormatError, WorldError
from slamtrials.worlds.world import World

__all__ = ["load_image", "read_pixels", "grey_levels", "DEFAULT_FREE_LEVEL", "DEFAULT_THRESHOLD"]

#: Grey level (0 black .. 1 white) at or above which a pixel is free.
DEFAULT_FREE_LEVEL = 0.9
#: Grey level below which a pixel counts as a wall (rather than unknown) in the statistics.
DEFAULT_THRESHOLD = 0.5

_SIXTEEN_BIT = {"I;16", "I;16L", "I;16B", "I;16N", "I"}


def read_pixels(path: str | Path) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
    """Read an image file into colour channels and an optional alpha channel.

    Parameters
    ----------
    path:
        Image file in any format Pillow reads (PNG, PGM/PPM, BMP, ...).

    Returns
    -------
    colour:
        float64 ``[H, W, C]`` with C = 1 (grey) or 3 (RGB), values on the 8-bit scale 0..255 (16-bit
        images are scaled by 255/65535, so they compare with the same thresholds). Row 0 is the top
        row of the picture. Palette images are expanded through their palette.
    alpha:
        float64 ``[H, W]`` on the scale 0..255, or ``None`` when the image has no alpha channel (a
        palette with a transparent entry counts as an alpha channel).

    Raises
    ------
    FormatError
        The file is missing, is not an image, is truncated or uses an unsupported pixel mode.
    """
    path = Path(path)
    try:
        with Image.open(path) as image:
            image.load()
            return _channels(path, image)
    except FileNotFoundError:
        raise FormatError(path, "no such image file") from None
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombError) as exc:
        raise FormatError(path, f"cannot read the image ({exc})") from exc


def _channels(path: Path, image: Image.Image) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
    mode = image.mode
    if mode in _SIXTEEN_BIT:
        values = np.clip(np.asarray(image).astype(np.float64), 0.0, 65535.0) * (255.0 / 65535.0)
        return values[:, :, None], None
    if mode == "F":
        raise FormatError(path, "floating-point images are not supported; save the floor plan as 8- or 16-bit grey")
    if mode == "1":
        image = image.convert("L")
    elif mode in ("La", "PA") or (mode == "P" and "transparency" in image.info):
        image = image.convert("LA" if mode == "La" else "RGBA")
    elif mode == "P" or mode not in ("L", "LA", "RGB", "RGBA"):
        image = image.convert("RGBA" if "A" in mode or "a" in mode else "RGB")
    values = np.asarray(image).astype(np.float64)
    if values.ndim == 2:
        return values[:, :, None], None
    if image.mode in ("LA", "RGBA"):
        return values[:, :, :-1], values[:, :, -1]
    return values, None


def grey_levels(colour: NDArray[np.float64], alpha: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
    """Grey level in [0, 1] of each pixel: the mean of the colour channels / 255; NaN where alpha is 0.

    Parameters
    ----------
    colour:
        ``[H, W, C]`` on the 8-bit scale, as from :func:`read_pixels`.
    alpha:
        ``[H, W]`` or ``None``. Fully transparent pixels carry no information and come out as NaN,
        which compares false with every level, i.e. neither free nor wall: unknown.
    """
    grey = colour.mean(axis=2) / 255.0
    if alpha is not None:
        grey = np.where(alpha > 0, grey, np.nan)
    return grey


def _check_level(name: str, value: float) -> float:
    try:
        level = float(value)
    except (TypeError, ValueError):
        raise WorldError(f"{name} must be a grey level between 0 and 1, got {value!r}") from None
    if not (0.0 <= level <= 1.0):
        raise WorldError(f"{name} must be a grey level between 0 (black) and 1 (white), got {value!r}")
    return level


def check_resolution(resolution: object, source: str | Path) -> float:
    """Validate a resolution (metres per pixel): a finite number > 0, else :class:`WorldError`."""
    if resolution is None:
        raise WorldError(
            f"{source}: a bare image has no scale; give its resolution in metres per pixel (e.g. resolution=0.05)"
        )
    if isinstance(resolution, bool):
        raise WorldError(f"{source}: resolution must be a number of metres per pixel, got {resolution!r}")
    try:
        value = float(resolution)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise WorldError(f"{source}: resolution must be a number of metres per pixel, got {resolution!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise WorldError(f"{source}: resolution must be a finite number of metres per pixel > 0, got {resolution!r}")
    return value


def as_pose(value: object, what: str, source: str | Path) -> NDArray[np.float64]:
    """``value`` as a float64 ``[3]`` pose (x, y, theta); two numbers mean theta = 0. Else :class:`WorldError`."""
    try:
        pose = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        pose = np.empty(0)
    if pose.shape == (2,):
        pose = np.append(pose, 0.0)
    if pose.shape != (3,) or not np.all(np.isfinite(pose)):
        raise WorldError(
            f"{source}: {what} must be finite numbers (x, y[, theta]) in metres and radians, got {value!r}"
        )
    return pose


def load_image(
    path: str | Path,
    *,
    resolution: float | None = None,
    threshold: float = DEFAULT_THRESHOLD,
    free_level: float = DEFAULT_FREE_LEVEL,
    negate: bool = False,
    origin: ArrayLike | Sequence[float] = (0.0, 0.0, 0.0),
    name: str | None = None,
    start: ArrayLike | None = None,
) -> World:
    """Load a floor-plan image as a :class:`World`.

    Parameters
    ----------
    path:
        PNG, PGM or any other image Pillow reads; any pixel mode (grey, 16-bit grey, palette, RGB,
        RGBA/LA where alpha 0 means unknown).
    resolution:
        Size of one pixel in metres (required: an image has no scale of its own).
    threshold:
        Grey level in [0, 1] below which a pixel is a wall rather than unknown (statistics only; both
        are obstacles in the simulation).
    free_level:
        Grey level in [0, 1] at or above which a pixel is free; everything darker is an obstacle.
        Must be >= ``threshold``. Pass ``free_level=threshold`` for a plain two-level split.
    negate:
        Swap black and white before classifying (for plans drawn white on black).
    origin:
        World pose (x, y, theta) in metres and radians of the lower-left corner of the image, as in a
        ROS map yaml. Two numbers mean theta = 0.
    name:
        World name; defaults to the file name without suffix.
    start:
        Robot start pose (x, y, theta) in the world frame; ``None`` lets :class:`World` pick one near
        the centre of the largest free region.

    Returns
    -------
    World
        ``occupied`` has the image's shape ``[H, W]`` (row 0 = top row of the picture); metadata holds
        ``source``, ``format`` ("image"), the levels used and the number of wall and unknown pixels.

    Raises
    ------
    WorldError
        Missing or invalid resolution, levels out of range, or no free pixel at all.
    FormatError
        The file cannot be read as an image.
    """
    path = Path(path)
    res = check_resolution(resolution, path)
    threshold = _check_level("threshold", threshold)
    free_level = _check_level("free_level", free_level)
    if threshold > free_level:
        raise WorldError(
            f"{path}: threshold ({threshold:g}) must not exceed free_level ({free_level:g}); "
            "pixels at or above free_level are free, pixels below threshold are walls"
        )
    pose = as_pose(origin, "origin", path)
    start_pose = None if start is None else as_pose(start, "start", path)
    colour, alpha = read_pixels(path)
    grey = grey_levels(colour, alpha)
    if negate:
        grey = 1.0 - grey
    free = grey >= free_level
    wall = grey < threshold
    if not free.any():
        raise WorldError(
            f"{path}: no free space: no pixel is at least as bright as free_level={free_level:g} "
            f"(brightest grey {np.nanmax(grey, initial=0.0):.3f}); check negate/free_level"
        )
    metadata = {
        "source": str(path),
        "format": "image",
        "image_size": [int(grey.shape[1]), int(grey.shape[0])],
        "free_level": free_level,
        "threshold": threshold,
        "negate": bool(negate),
        "wall_pixels": int(np.count_nonzero(wall)),
        "unknown_pixels": int(np.count_nonzero(~free & ~wall)),
    }
    return World(
        occupied=~free,
        resolution=res,
        origin=pose,
        name=name or path.stem,
        start=start_pose,
        metadata=metadata,
    )
