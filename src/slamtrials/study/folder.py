"""The study folder: its manifest (``study.json``) and one campaign folder per cell.

::

    <study>/
      study.json          format tag, the study config, its digest, the cells (name, settings, folder)
      cells/<cell>/       a normal campaign folder (``slamtrials report`` and ``compare`` work on it)
      report/             the study page (``slamtrials study report``)

:func:`check_study_folder` decides, touching nothing, whether a study may start or resume in a folder:
a new or empty folder, or one whose manifest holds the same study (same digest). A folder of another
study config is refused naming every changed key (``axes.sim.laser.max_range: stored [30, 15], given
[30, 20]``), a campaign folder or any other non-empty folder is refused too; nothing in it is changed.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from slamtrials.__about__ import __version__
from slamtrials.atomicfile import atomic_write_text
from slamtrials.campaign.store import DB_FILE, differing_fields
from slamtrials.errors import ConfigError, FormatError
from slamtrials.study.cells import CELLS_DIR, Cell
from slamtrials.study.config import StudyConfig

__all__ = [
    "MANIFEST_FILE",
    "STUDY_FORMAT",
    "StudyManifest",
    "is_study",
    "check_study_folder",
    "read_manifest",
    "write_manifest",
    "changed_keys",
]

MANIFEST_FILE = "study.json"
STUDY_FORMAT = "slamtrials-study/1"
#: Changed keys named in full in a refusal (the rest are counted).
_SHOWN_CHANGES = 6


@dataclass(frozen=True)
class StudyManifest:
    """What ``study.json`` holds.

    Attributes
    ----------
    config:
        The study config.
    digest:
        Its digest (:meth:`StudyConfig.digest`) when stored.
    identity:
        Its identity (:meth:`StudyConfig.identity`) when stored, to name what changed.
    cells:
        ``[{"name", "settings": {key: value}, "combination", "folder"}]`` in cell order.
    created, version:
        When and by which slamtrials version the study was started.
    """

    config: StudyConfig
    digest: str
    identity: dict[str, Any]
    cells: tuple[dict[str, Any], ...]
    created: str
    version: str


def is_study(folder: str | Path) -> bool:
    """Whether ``folder`` holds a study manifest."""
    return (Path(folder) / MANIFEST_FILE).is_file()


def read_manifest(folder: str | Path) -> StudyManifest:
    """The manifest of the study in ``folder``.

    Raises
    ------
    ConfigError
        No study there.
    FormatError
        A manifest that is not JSON or not of this format.
    """
    path = Path(folder) / MANIFEST_FILE
    if not path.is_file():
        raise ConfigError(f"{folder}: not a study folder ({MANIFEST_FILE} missing); give a study config to start one")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FormatError(path, f"not a study manifest ({exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != STUDY_FORMAT:
        got = doc.get("format") if isinstance(doc, dict) else None
        raise FormatError(path, f"expected a study manifest of format {STUDY_FORMAT}, got {got!r}")
    return StudyManifest(
        config=StudyConfig.from_dict(doc["config"], source=str(path)),
        digest=str(doc["digest"]),
        identity=dict(doc["identity"]),
        cells=tuple(doc["cells"]),
        created=str(doc.get("created", "")),
        version=str(doc.get("version", "")),
    )


def changed_keys(stored: dict[str, Any], given: dict[str, Any]) -> str:
    """``key: stored X, given Y; ...`` for the settings that differ between two study identities."""
    changes = differing_fields(stored, given)
    parts = [f"{k}: stored {json.dumps(a)}, given {json.dumps(b)}" for k, a, b in changes[:_SHOWN_CHANGES]]
    if len(changes) > _SHOWN_CHANGES:
        parts.append(f"and {len(changes) - _SHOWN_CHANGES} more")
    return "; ".join(parts)


def check_study_folder(folder: str | Path, config: StudyConfig) -> bool:
    """Whether ``folder`` already holds this study (True) or is new (False); touches nothing.

    Raises
    ------
    ConfigError
        The folder holds another study (the changed keys named), a campaign, or other files.
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ConfigError(f"{folder}: exists and is not a folder; choose another study folder")
    if is_study(folder):
        stored = read_manifest(folder)
        if stored.digest != config.digest():
            raise ConfigError(
                f"{folder}: holds a study with another config ({changed_keys(stored.identity, config.identity())}); "
                "resume it with its own config or choose another folder"
            )
        return True
    if (folder / DB_FILE).is_file():
        raise ConfigError(f"{folder}: holds a campaign, not a study; choose another folder for the study")
    if folder.is_dir():
        others = sorted(p.name for p in folder.iterdir())
        if others:
            raise ConfigError(
                f"{folder}: is not empty and holds no study ({MANIFEST_FILE} missing; found {', '.join(others[:3])}); "
                "choose a new or empty folder"
            )
    return False


def cell_entry(cell: Cell) -> dict[str, Any]:
    """A cell as the manifest lists it."""
    return {
        "name": cell.name,
        "settings": {k: v for k, v in cell.settings},
        "combination": cell.combination,
        "folder": f"{CELLS_DIR}/{cell.name}",
    }


def write_manifest(folder: str | Path, config: StudyConfig, cells: list[Cell]) -> Path:
    """Write ``study.json`` (atomically; the folder is created if needed)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    doc = {
        "format": STUDY_FORMAT,
        "config": config.model_dump(mode="json"),
        "digest": config.digest(),
        "identity": config.identity(),
        "cells": [cell_entry(c) for c in cells],
        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "version": __version__,
    }
    return atomic_write_text(folder / MANIFEST_FILE, json.dumps(doc, indent=2, sort_keys=False) + "\n")
