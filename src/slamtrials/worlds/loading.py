"""One entry point for every floor-plan source: :func:`load_world`.

A source is a bundled catalog name, or a file whose format is chosen by its suffix (or by ``fmt``):

==============  =========  ===========================================================
format name     suffixes   loader
==============  =========  ===========================================================
``image``       .png .pgm  :func:`slamtrials.worlds.formats.image.load_image` (needs a resolution)
``rosmap``      .yaml .yml :func:`slamtrials.worlds.formats.rosmap.load_rosmap`
``stage``       .world     :func:`slamtrials.worlds.formats.stage.load_stage_world`
``houseexpo``   .json      :func:`slamtrials.worlds.formats.houseexpo.load_houseexpo`
==============  =========  ===========================================================
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from slamtrials.errors import WorldError
from slamtrials.worlds.world import World

__all__ = ["load_world", "WORLD_FORMATS", "SUFFIX_FORMATS"]


def _image(path: Path, **options: Any) -> World:
    from slamtrials.worlds.formats.image import load_image

    return load_image(path, **options)


def _rosmap(path: Path, **options: Any) -> World:
    from slamtrials.worlds.formats.rosmap import load_rosmap

    return load_rosmap(path, **options)


def _stage(path: Path, **options: Any) -> World:
    from slamtrials.worlds.formats.stage import load_stage_world

    return load_stage_world(path, **options)


def _houseexpo(path: Path, **options: Any) -> World:
    from slamtrials.worlds.formats.houseexpo import load_houseexpo

    return load_houseexpo(path, **options)


#: Format name -> loader ``(path, **options) -> World``. Loaders import lazily to keep start-up fast.
WORLD_FORMATS: dict[str, Callable[..., World]] = {
    "image": _image,
    "rosmap": _rosmap,
    "stage": _stage,
    "houseexpo": _houseexpo,
}

SUFFIX_FORMATS: dict[str, str] = {
    ".png": "image",
    ".pgm": "image",
    ".yaml": "rosmap",
    ".yml": "rosmap",
    ".world": "stage",
    ".json": "houseexpo",
}


def load_world(source: str | Path, *, fmt: str | None = None, **options: Any) -> World:
    """Load a world from a catalog name or a floor-plan file.

    Parameters
    ----------
    source:
        A bundled catalog name (see ``slamtrials worlds list``) or a path to a floor-plan file.
    fmt:
        Force a format (a key of :data:`WORLD_FORMATS`) instead of guessing it from the suffix.
    **options:
        Passed to the format's loader, e.g. ``resolution=0.05`` for a bare image or ``threshold``.

    Raises
    ------
    WorldError
        Unknown catalog name, unknown format, or a floor plan that cannot be simulated.
    FormatError
        The file does not follow its format.
    """
    path = Path(source)
    if fmt is None and not path.exists():
        from slamtrials.worlds.catalog import catalog_entry, load_catalog_world

        if path.suffix or len(path.parts) > 1:
            raise WorldError(f"{source}: no such floor-plan file")
        catalog_entry(str(source))  # an unknown name raises, suggesting close names
        return load_catalog_world(str(source))
    if path.is_dir():
        raise WorldError(f"{path}: is a folder; give a floor-plan file ({', '.join(sorted(SUFFIX_FORMATS))})")
    fmt = fmt or SUFFIX_FORMATS.get(path.suffix.lower())
    if fmt not in WORLD_FORMATS:
        raise WorldError(
            f"{path}: unknown floor-plan format {fmt or path.suffix!r}; expected one of {', '.join(sorted(SUFFIX_FORMATS))}"
        )
    try:
        return WORLD_FORMATS[fmt](path, **options)
    except TypeError as exc:
        if "unexpected keyword argument" not in str(exc):
            raise
        raise WorldError(f"{path}: option not valid for the {fmt} format ({exc})") from None
