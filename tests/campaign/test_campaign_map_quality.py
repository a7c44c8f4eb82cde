"""Map quality kept by a campaign: run.json's ``map_quality``, the catalog's details, summary.csv's means, the
report's worlds table; replays score their own map, and say so where the world no longer loads."""

from __future__ import annotations

import csv
import json
import math
import shutil
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from slamtrials.campaign import load_summary, run_campaign
from slamtrials.campaign.mapscore import floor_plan, score_map
from slamtrials.campaign.mapsummary import MAP_QUALITY_CSV_COLUMNS, world_map_quality
from slamtrials.campaign.replay import replay_campaign
from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.campaign.worldset import load_world_cached
from slamtrials.geometry import compose, inverse
from slamtrials.metric.mapquality import MAP_QUALITY_FIGURES, MAP_QUALITY_KEY, MapQuality
from slamtrials.record import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, RunRecord
from slamtrials.worlds import World

from .conftest import write_room

PERFECT = (1.0, 1.0, 1.0, 1.0, 1.0, 0.0)


@dataclass(frozen=True)
class PerfectMapTrial:
    """A run whose map is the world's reachable space and visible walls, drawn in a map frame turned by -90
    degrees and moved, with the estimate in that frame: scored through the fit, it is a perfect map."""

    def __call__(self, world: World, config, seed: int) -> RunRecord:
        record = FakeTrial()(world, config, seed)
        truth = np.array([world.start, compose(world.start, [1.5, 0.3, 0.4])])
        reachable = world.reachable_free()
        faces = world.occupied & ndimage.binary_dilation(reachable, structure=ndimage.generate_binary_structure(2, 1))
        grid = np.full(world.occupied.shape, UNKNOWN, dtype=np.int8)
        grid[reachable] = FREE
        grid[faces] = OCCUPIED
        a, b = 2.5, -7.0  # the map's lower-left corner in the map frame
        ox, oy, _ = world.origin
        world_from_map = np.array([ox - b, oy + world.height * world.resolution + a, -math.pi / 2])
        record = replace(record, truth=truth, odometry=truth.copy())
        record.estimate = compose(inverse(world_from_map), truth)
        record.map = OccupancyGrid(np.rot90(grid).copy(), world.resolution, np.array([a, b, 0.0]))
        record.metadata = FakeTrial()(world, config, seed).metadata
        return record


@pytest.fixture(scope="module")
def mapped(tmp_path_factory, rooms, client, five_run_config):
    folder = tmp_path_factory.mktemp("mapped") / "c"
    run_campaign(five_run_config(rooms[:1]), folder, scheduler=client, trial_fn=PerfectMapTrial())
    return folder


def _run_docs(folder: Path) -> list[tuple[dict, dict]]:
    with CampaignStore.open(folder) as store:
        runs = store.runs()
    return [(json.loads((folder / run.folder / "run.json").read_text()), json.loads(run.details)) for run in runs]


def test_run_json_and_the_catalog_keep_the_map_quality_of_each_run(mapped):
    docs = _run_docs(mapped)
    assert len(docs) == 5
    for doc, details in docs:
        quality = MapQuality.of(doc)
        assert doc[MAP_QUALITY_KEY]["format"] == "slamtrials-mapquality/1"
        assert quality is not None and tuple(quality.figures().values()) == PERFECT
        assert quality.alignment_rms_m == pytest.approx(0.0, abs=1e-9) and quality.cell_m == 0.05
        assert {name: details[name] for name in MAP_QUALITY_FIGURES} == quality.figures()


def test_summary_csv_and_the_report_tables_hold_the_world_means(mapped):
    from slamtrials.report.load import load_campaign

    (row,) = load_summary(mapped)
    assert row.map_quality is not None and row.map_quality.runs == 5 and row.map_quality.means() == PERFECT
    (csv_row,) = csv.DictReader((mapped / "summary.csv").open())
    assert tuple(float(csv_row[c]) for c in MAP_QUALITY_CSV_COLUMNS) == PERFECT
    worlds = load_campaign(mapped).worlds
    assert tuple(float(worlds[c].iloc[0]) for c in MAP_QUALITY_CSV_COLUMNS) == PERFECT


def test_a_world_mean_is_over_the_runs_that_recorded_each_figure():
    quality = world_map_quality([{"free_iou": 0.5, "occupied_precision_1": None}, {"free_iou": 1.0}, {"eps_t": 0.1}])
    assert quality is not None and quality.runs == 2 and quality.free_iou == 0.75
    assert quality.occupied_precision_1 is None
    assert world_map_quality([{"eps_t": 0.1}]) is None


def test_a_replay_scores_its_own_map_not_the_source_s(mapped, tmp_path, client):
    replay_campaign(mapped, tmp_path / "r", scheduler=client)
    for doc, details in _run_docs(tmp_path / "r"):
        quality = MapQuality.of(doc)
        assert quality is not None and quality.figures() != dict(zip(MAP_QUALITY_FIGURES, PERFECT))
        assert {name: details[name] for name in MAP_QUALITY_FIGURES} == quality.figures()
        assert "map_quality" not in doc["replay"]


def test_a_replay_whose_world_no_longer_loads_says_so_and_stores_none(tmp_path, client, five_run_config):
    plans = tmp_path / "plans"
    run_campaign(
        five_run_config([write_room(plans, "moved")]), tmp_path / "c", scheduler=client, trial_fn=PerfectMapTrial()
    )
    shutil.rmtree(plans)
    load_world_cached.cache_clear()
    replay_campaign(tmp_path / "c", tmp_path / "r", scheduler=client)
    for doc, details in _run_docs(tmp_path / "r"):
        assert MAP_QUALITY_KEY not in doc and all(details.get(name) is None for name in MAP_QUALITY_FIGURES)
        assert doc["replay"]["map_quality"].startswith("not scored: the world")
    (row,) = load_summary(tmp_path / "r")
    assert row.map_quality is None


def test_score_map_needs_a_map_and_an_estimate(rooms):
    world = load_world_cached(rooms[0])
    record = FakeTrial()(world, None, 1)
    assert score_map(replace(record, map=None), world) is None
    assert floor_plan(world).reachable.sum() == world.reachable_free().sum()
