"""The worlds of a campaign: expanding the config's entries and checking that each one loads.

An entry of ``worlds`` is

* a bundled catalog name (``office_small_01``): the world's name is the catalog name;
* a floor-plan file (map_server ``.yaml``/``.yml``, Stage ``.world``, HouseExpo ``.json``): its name is
  the file stem, or the folder's name for the generic ``map.yaml`` of a map_server folder (as
  :func:`~slamtrials.worlds.load_world` names it: ``real/hbrs_c069/map.yaml`` -> ``hbrs_c069``);
* a folder: every floor plan inside it, searched recursively, in sorted order of relative path. A
  ``.yaml`` counts only when it is a map_server map (it has an ``image`` key). A plan directly in the
  folder is named by its stem (a generic ``map.yaml`` by the folder's name); one in a subfolder by the subfolder path (``a/b`` -> ``a-b``) when it is
  the only plan there, else by that path and its stem (``a-b-stem``).

Names are the run folders' names (``runs/<name>/``) and key each run's seed, so they must be unique;
characters other than letters, digits, ``.``, ``_`` and ``-`` become ``_``. Bare images (``.png``) need
a resolution: give them a map_server ``.yaml``.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import yaml

from slamtrials.campaign.store import WorldInfo
from slamtrials.errors import ConfigError, SlamtrialsError
from slamtrials.worlds import World, load_world

__all__ = ["expand_worlds", "resolve_worlds", "load_world_cached", "PLAN_SUFFIXES"]

#: Suffixes of the floor plans a folder entry expands to.
PLAN_SUFFIXES = (".yaml", ".yml", ".world", ".json")


def _clean(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".") or "world"


def _stem_name(path: Path) -> str:
    """A plan file's own name: its stem, or its folder's name for a generic map_server ``map.yaml``."""
    if path.stem == "map" and path.suffix.lower() in (".yaml", ".yml") and path.parent.name:
        return path.parent.name
    return path.stem


def _is_map_yaml(path: Path) -> bool:
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return True  # let the loader report what is wrong with it
    return isinstance(doc, dict) and "image" in doc


def _plans_in(folder: Path) -> list[Path]:
    plans = []
    for path in sorted(folder.rglob("*"), key=lambda p: p.relative_to(folder).as_posix()):
        if not path.is_file() or path.suffix.lower() not in PLAN_SUFFIXES:
            continue
        if any(part.startswith(".") for part in path.relative_to(folder).parts):
            continue
        if path.suffix.lower() in (".yaml", ".yml") and not _is_map_yaml(path):
            continue
        plans.append(path)
    return plans


def expand_worlds(entries: Sequence[str], *, base: str | Path | None = None) -> list[tuple[str, str, str]]:
    """Expand world entries into ``(name, ref, entry)`` triples, in order.

    Parameters
    ----------
    entries:
        The config's ``worlds``.
    base:
        Folder that relative paths are relative to (default: the working directory).

    Returns
    -------
    list of (name, ref, entry)
        ``ref`` is the catalog name or the absolute path of the floor plan; ``entry`` the config entry it
        came from.

    Raises
    ------
    ConfigError
        A folder without floor plans, or two worlds with the same name.
    """
    base = Path.cwd() if base is None else Path(base)
    out: list[tuple[str, str, str]] = []
    for entry in entries:
        path = Path(entry).expanduser()
        path = path if path.is_absolute() else base / path
        if path.is_dir():
            plans = _plans_in(path)
            if not plans:
                raise ConfigError(f"worlds: folder {entry!r} holds no floor plan ({', '.join(PLAN_SUFFIXES)})")
            per_folder: dict[Path, int] = {}
            for plan in plans:
                per_folder[plan.parent] = per_folder.get(plan.parent, 0) + 1
            for plan in plans:
                rel = plan.parent.relative_to(path)
                if rel == Path("."):
                    name = _stem_name(plan)
                elif per_folder[plan.parent] == 1:
                    name = "-".join(rel.parts)
                else:
                    name = "-".join((*rel.parts, plan.stem))
                out.append((_clean(name), str(plan.resolve()), entry))
        elif path.exists():
            out.append((_clean(_stem_name(path)), str(path.resolve()), entry))
        else:
            out.append((_clean(entry), entry, entry))  # a catalog name (load_world reports unknown ones)
    seen: dict[str, str] = {}
    for name, ref, _entry in out:
        if name in seen:
            raise ConfigError(
                f"worlds: two worlds are named {name!r} ({seen[name]} and {ref}); rename one of the files"
            )
        seen[name] = ref
    return out


@lru_cache(maxsize=16)
def load_world_cached(ref: str) -> World:
    """:func:`slamtrials.worlds.load_world`, cached per process (workers run many runs of a world)."""
    return load_world(ref)


def resolve_worlds(
    entries: Sequence[str], *, base: str | Path | None = None, robot_radius: float | None = None
) -> list[WorldInfo]:
    """Expand the entries and load every world once, before any work starts.

    Each world's ``reachable_area`` is what a disc robot of ``robot_radius`` (m) can cover from the start
    (:meth:`World.reachable_by_disc`, the area the trials' mapped fraction refers to), or without a
    radius every free cell connected to the start.

    Raises
    ------
    ConfigError
        A world that does not load (naming its entry and the loader's message), a folder without plans,
        or duplicate names.
    """
    infos = []
    for position, (name, ref, entry) in enumerate(expand_worlds(entries, base=base)):
        try:
            world = load_world_cached(ref)
            reachable = world.reachable_free() if robot_radius is None else world.reachable_by_disc(robot_radius)
            area = world.area_of(reachable)
        except (SlamtrialsError, OSError) as exc:
            where = f"world {entry!r}" if entry == ref else f"world {ref} (from {entry!r})"
            raise ConfigError(f"worlds: {where} does not load: {exc}") from None
        infos.append(WorldInfo(name, ref, position, area))
    return infos
