"""The bundled catalog of generated worlds: names, descriptions, and loading one by name.

The worlds live in the package's ``data`` folder as ROS maps (``<name>.png`` + ``<name>.yaml``), with
``catalog.yaml`` listing them; :mod:`slamtrials.worlds.catalog_build` writes them.
"""

from __future__ import annotations

import difflib
import shutil
import tempfile
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from slamtrials.errors import WorldError
from slamtrials.worlds.world import World

__all__ = ["catalog_names", "catalog_entries", "load_catalog_world", "catalog_entry"]

_DATA = "data"
_INDEX = "catalog.yaml"


def _data_dir():
    return resources.files("slamtrials.worlds").joinpath(_DATA)


@lru_cache(maxsize=1)
def _index() -> tuple[dict[str, Any], ...]:
    index = _data_dir().joinpath(_INDEX)
    if not index.is_file():
        return ()
    doc = yaml.safe_load(index.read_text(encoding="utf-8")) or {}
    return tuple(dict(record) for record in doc.get("worlds", []))


def catalog_entries() -> list[dict[str, Any]]:
    """The catalog records, in catalog order.

    Each record has ``name``, ``kind``, ``shape``, ``area_m2`` (requested free area), ``free_area_m2``,
    ``seed``, ``width_m``, ``height_m``, ``rooms`` and ``description``.
    """
    return [dict(record) for record in _index()]


def catalog_names() -> list[str]:
    """Names of the bundled worlds, in catalog order."""
    return [record["name"] for record in _index()]


def catalog_entry(name: str) -> dict[str, Any]:
    """The catalog record of one world.

    Raises
    ------
    WorldError
        No bundled world has that name; the message suggests close names.
    """
    for record in _index():
        if record["name"] == name:
            return dict(record)
    names = catalog_names()
    close = difflib.get_close_matches(name, names, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else f"; bundled worlds: {', '.join(names)}"
    raise WorldError(f"no bundled world named {name!r}{hint}")


def load_catalog_world(name: str) -> World:
    """Load a bundled world by name.

    Raises
    ------
    WorldError
        Unknown name (the message lists close names).
    """
    from slamtrials.worlds.formats.rosmap import load_rosmap

    catalog_entry(name)
    yaml_file = _data_dir().joinpath(f"{name}.yaml")
    if isinstance(yaml_file, Path):
        return load_rosmap(yaml_file, name=name)
    with tempfile.TemporaryDirectory() as tmp:  # package inside a zip: copy the map out first
        for suffix in (".yaml", ".png"):
            source = _data_dir().joinpath(f"{name}{suffix}")
            with source.open("rb") as src, open(Path(tmp) / f"{name}{suffix}", "wb") as dst:
                shutil.copyfileobj(src, dst)
        return load_rosmap(Path(tmp) / f"{name}.yaml", name=name)
