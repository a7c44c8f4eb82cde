"""Build the bundled catalog of worlds (run once by ``bench/make_catalog.py``).

Each generated entry is regenerated from its (kind, area, seed) by
:func:`slamtrials.worlds.generate.generate_world`, and each replica of the paper's validation settings is
drawn by :func:`slamtrials.worlds.replicas.build_replica`; both are written as ROS maps (``<name>.png`` +
``<name>.yaml``) into the data folder, with ``catalog.yaml`` listing every world (generated ones first).
The test suite regenerates every entry and checks the stored image bit for bit, so a change to the
generator or to a replica's drawing must rebuild the catalog (and bump ``GENERATOR_VERSION`` or
``REPLICA_VERSION``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import yaml

from slamtrials.atomicfile import atomic_write_text
from slamtrials.worlds.formats.rosmap_save import save_rosmap
from slamtrials.worlds.generate import GENERATOR_VERSION, KINDS, generate_world
from slamtrials.worlds.replicas import REPLICA_VERSION, REPLICAS, ReplicaSpec, build_replica
from slamtrials.worlds.world import World

__all__ = [
    "CatalogEntry",
    "CATALOG",
    "CATALOG_FILE",
    "RESOLUTION",
    "REPLICAS",
    "build_catalog",
    "build_entry",
    "describe",
]

#: Name of the index file in the data folder.
CATALOG_FILE = "catalog.yaml"
#: Resolution (m/px) of every bundled world.
RESOLUTION = 0.05


@dataclass(frozen=True)
class CatalogEntry:
    """One bundled world: its name and the arguments that generate it (area = requested free m^2)."""

    name: str
    kind: str
    area: float
    seed: int


#: The bundled worlds: small ones (for demos and tests), medium and large ones.
CATALOG: tuple[CatalogEntry, ...] = (
    CatalogEntry("office_small_01", "office", 150, 11),
    CatalogEntry("office_small_02", "office", 280, 3),
    CatalogEntry("school_small_01", "school", 260, 2),
    CatalogEntry("lab_small_01", "lab", 180, 4),
    CatalogEntry("lab_small_02", "lab", 350, 1),
    CatalogEntry("house_small_01", "house", 110, 1),
    CatalogEntry("house_small_02", "house", 220, 5),
    CatalogEntry("office_medium_01", "office", 700, 1),
    CatalogEntry("office_medium_02", "office", 1600, 11),
    CatalogEntry("school_medium_01", "school", 1000, 0),
    CatalogEntry("school_medium_02", "school", 1900, 12),
    CatalogEntry("lab_medium_01", "lab", 600, 2),
    CatalogEntry("lab_medium_02", "lab", 1300, 10),
    CatalogEntry("multiwing_medium_01", "multiwing", 1200, 0),
    CatalogEntry("multiwing_medium_02", "multiwing", 2000, 0),
    CatalogEntry("office_large_01", "office", 4000, 4),
    CatalogEntry("school_large_01", "school", 6000, 1),
    CatalogEntry("lab_large_01", "lab", 3000, 14),
    CatalogEntry("multiwing_large_01", "multiwing", 10000, 0),
    CatalogEntry("multiwing_large_02", "multiwing", 5000, 4),
)


def build_entry(entry: CatalogEntry) -> World:
    """Generate the world of one catalog entry."""
    return generate_world(entry.kind, entry.area, seed=entry.seed, resolution=RESOLUTION, name=entry.name)


def describe(world: World) -> str:
    """One line about a generated world: kind, shape, rooms and doors."""
    meta = world.metadata
    kind = meta["kind"]
    return (
        f"{kind} ({KINDS[kind].description}); {meta['shape']} shape, {meta['rooms']} rooms, {len(meta['doors'])} doors"
    )


def _save(world: World, out_dir: Path) -> None:
    save_rosmap(world, out_dir / f"{world.name}.yaml")
    for suffix in (".yaml", ".png"):  # readable by everyone once installed
        (out_dir / f"{world.name}{suffix}").chmod(0o644)


def replica_record(spec: ReplicaSpec, world: World) -> dict:
    """The catalog record of a replica: ``area_m2`` is its floor area (before furniture), ``seed`` null."""
    width, height = world.size_m
    return {
        "name": spec.name,
        "kind": "replica",
        "shape": spec.shape,
        "area_m2": float(world.metadata["floor_area_m2"]),
        "free_area_m2": round(world.free_area, 1),
        "seed": None,
        "width_m": round(width, 2),
        "height_m": round(height, 2),
        "rooms": 1,
        "description": spec.description,
        "source": spec.source,
        "layout": spec.layout,
    }


def build_catalog(
    out_dir: str | Path, entries: tuple[CatalogEntry, ...] = CATALOG, replicas: tuple[ReplicaSpec, ...] = REPLICAS
) -> list[dict]:
    """Generate every entry and draw every replica into ``out_dir`` (``<name>.png``, ``<name>.yaml``) and
    write ``catalog.yaml``.

    Returns the catalog records (also the content of ``catalog.yaml``'s ``worlds`` list).
    """
    out_dir = Path(out_dir)
    records = []
    for entry in entries:
        world = build_entry(entry)
        _save(world, out_dir)
        width, height = world.size_m
        records.append(
            {
                "name": entry.name,
                "kind": entry.kind,
                "shape": world.metadata["shape"],
                "area_m2": float(entry.area),
                "free_area_m2": round(world.free_area, 1),
                "seed": entry.seed,
                "width_m": round(width, 2),
                "height_m": round(height, 2),
                "rooms": world.metadata["rooms"],
                "description": describe(world),
            }
        )
    for spec in replicas:
        world = build_replica(spec.name, resolution=RESOLUTION)
        _save(world, out_dir)
        records.append(replica_record(spec, world))
    doc = {
        "generator_version": GENERATOR_VERSION,
        "replica_version": REPLICA_VERSION,
        "resolution": RESOLUTION,
        "note": "area_m2 is the requested free area; regenerate with generate_world(kind, area_m2, seed=seed); "
        "kind replica: the paper's validation settings drawn by slamtrials.worlds.replicas (area_m2 = floor area)",
        "worlds": records,
    }
    atomic_write_text(out_dir / CATALOG_FILE, yaml.safe_dump(doc, sort_keys=False, width=120))
    (out_dir / CATALOG_FILE).chmod(0o644)
    return records
