"""The bundled catalog: every world loads, is what it claims, and is regenerated bit for bit."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest
import yaml
from scipy import ndimage

from slamtrials.errors import WorldError
from slamtrials.worlds import load_world
from slamtrials.worlds.catalog import catalog_entries, catalog_entry, catalog_names, load_catalog_world
from slamtrials.worlds.catalog_build import CATALOG, CATALOG_FILE, REPLICAS, build_entry
from slamtrials.worlds.generate import GENERATOR_VERSION
from slamtrials.worlds.replicas import REPLICA_VERSION, build_replica

DATA = resources.files("slamtrials.worlds").joinpath("data")
NAMES = catalog_names()
LARGE = {e.name for e in CATALOG if e.area > 2500}


def test_catalog_lists_the_entries_of_the_build_script():
    assert NAMES == [e.name for e in CATALOG] + [r.name for r in REPLICAS]
    assert len(NAMES) == len(set(NAMES)) >= 23
    records = {r["name"]: r for r in catalog_entries()}
    for entry in CATALOG:
        record = records[entry.name]
        assert (record["kind"], record["area_m2"], record["seed"]) == (entry.kind, entry.area, entry.seed)
        assert record["description"]
    for replica in REPLICAS:
        record = records[replica.name]
        assert (record["kind"], record["shape"], record["seed"]) == ("replica", replica.shape, None)
        assert record["source"] == replica.source and "guess" in record["layout"]


def test_catalog_spans_small_medium_and_large_buildings():
    entries = catalog_entries()
    small = [e for e in entries if e["free_area_m2"] < 300]
    assert len(small) >= 4 and len({e["kind"] for e in small}) >= 3
    assert sum(500 <= e["free_area_m2"] <= 2000 for e in entries) >= 5
    assert any(e["free_area_m2"] >= 9000 for e in entries)
    assert {e["kind"] for e in entries} >= {"office", "school", "lab", "multiwing", "house"}
    assert len({e["shape"] for e in entries}) >= 6


def test_catalog_file_records_the_generator_version():
    doc = yaml.safe_load(DATA.joinpath(CATALOG_FILE).read_text())
    assert doc["generator_version"] == GENERATOR_VERSION
    assert doc["replica_version"] == REPLICA_VERSION


def test_catalog_data_stays_small():
    with resources.as_file(DATA) as folder:
        total = sum(f.stat().st_size for f in folder.iterdir() if f.is_file())
    assert total < 3_000_000


@pytest.mark.parametrize("name", [pytest.param(n, marks=[pytest.mark.slow] if n in LARGE else []) for n in NAMES])
def test_every_world_loads_and_is_what_it_claims(name):
    world = load_catalog_world(name)
    record = catalog_entry(name)
    assert world.name == name
    assert world.metadata["kind"] == record["kind"]
    assert world.metadata["shape"] == record["shape"]
    assert world.resolution == 0.05
    assert world.free_area == pytest.approx(record["free_area_m2"], abs=0.1)
    assert world.size_m == pytest.approx((record["width_m"], record["height_m"]), abs=0.01)
    _, regions = ndimage.label(~world.occupied)
    assert regions == 1
    assert world.reachable_free().sum() == np.count_nonzero(~world.occupied)


def test_catalog_names_load_through_load_world():
    world = load_world("office_small_01")
    assert world.name == "office_small_01" and world.metadata["kind"] == "office"


@pytest.mark.parametrize(
    "entry", [pytest.param(e, id=e.name, marks=[pytest.mark.slow] if e.name in LARGE else []) for e in CATALOG]
)
def test_catalog_world_is_regenerated_bit_for_bit(entry):
    stored = load_catalog_world(entry.name)
    fresh = build_entry(entry)
    assert fresh.occupied.shape == stored.occupied.shape
    assert np.array_equal(fresh.occupied, stored.occupied)
    assert np.allclose(fresh.start, stored.start, atol=1e-6)
    assert np.allclose(fresh.origin, stored.origin)


@pytest.mark.parametrize("replica", REPLICAS, ids=lambda r: r.name)
def test_catalog_replica_is_redrawn_bit_for_bit(replica):
    stored = load_catalog_world(replica.name)
    fresh = build_replica(replica.name)
    assert np.array_equal(fresh.occupied, stored.occupied)
    assert np.allclose(fresh.start, stored.start, atol=1e-6)
    assert np.allclose(fresh.origin, stored.origin)
    assert fresh.metadata.items() <= stored.metadata.items()  # the loader adds the file format


def test_unknown_name_suggests_close_names():
    with pytest.raises(WorldError) as info:
        load_catalog_world("office_smal_01")
    assert "office_small_01" in str(info.value)
    with pytest.raises(WorldError) as info:
        catalog_entry("zzz")
    assert "bundled worlds" in str(info.value)
