"""How fast runs explored, kept by a campaign: the catalog's details, summary.csv's per-world figures, and
catalogs of runs that recorded none."""

from __future__ import annotations

import csv
import json

import pytest

from slamtrials.campaign import load_summary, run_campaign
from slamtrials.campaign.explorationsummary import EXPLORATION_CSV_COLUMNS, world_exploration
from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.trial.exploration import EXPLORATION_FIGURES, exploration_measures

MEASURES = exploration_measures([0.0, 30.0, 60.0, 90.0], [0.1, 0.92, 0.97, 0.98], [0.0, 9.0, 17.0, 25.0], "fake")


@pytest.fixture(scope="module")
def explored(tmp_path_factory, rooms, client, five_run_config):
    folder = tmp_path_factory.mktemp("explored") / "c"
    run_campaign(five_run_config(rooms[:1]), folder, scheduler=client, trial_fn=FakeTrial(exploration=MEASURES))
    return folder


def test_the_catalog_and_summary_csv_keep_how_the_runs_explored(explored):
    with CampaignStore.open(explored) as store:
        details = [json.loads(run.details) for run in store.runs()]
    assert len(details) == 5
    assert all({name: d[name] for name in EXPLORATION_FIGURES} == MEASURES.figures() for d in details)
    (row,) = load_summary(explored)
    assert row.exploration is not None
    assert row.exploration.cells() == (5, pytest.approx(0.98), 5, 30.0, 9.0, 0, None, None)
    (csv_row,) = csv.DictReader((explored / "summary.csv").open())
    cells = [csv_row[c] for c in EXPLORATION_CSV_COLUMNS]
    assert float(cells[1]) == pytest.approx(0.98)
    assert cells[:1] + cells[2:] == ["5", "5", "30.0", "9.0", "0", "", ""]


def test_runs_without_exploration_measures_leave_the_cells_empty(tmp_path, rooms, client, five_run_config):
    run_campaign(five_run_config(rooms[:1]), tmp_path / "c", scheduler=client, trial_fn=FakeTrial())
    (row,) = load_summary(tmp_path / "c")
    assert row.exploration is None
    (csv_row,) = csv.DictReader((tmp_path / "c" / "summary.csv").open())
    assert all(csv_row[c] == "" for c in EXPLORATION_CSV_COLUMNS)


def test_a_world_exploration_averages_the_runs_that_reached_each_threshold():
    found = world_exploration(
        [
            {"final_coverage": 0.995, "time_to_90_s": 100.0, "distance_to_90_m": 30.0, "time_to_99_s": 200.0},
            {"final_coverage": 0.95, "time_to_90_s": 140.0, "distance_to_90_m": 50.0, "time_to_99_s": None},
            {"final_coverage": 0.5},
            {"slam_cpu_s": 1.0},  # a run of an earlier version: not counted
        ]
    )
    assert found is not None and found.runs == 3
    assert found.coverage_final == pytest.approx((0.995 + 0.95 + 0.5) / 3)
    assert (found.reached_90, found.time_to_90_s, found.distance_to_90_m) == (2, 120.0, 40.0)
    assert (found.reached_99, found.time_to_99_s, found.distance_to_99_m) == (1, 200.0, None)
    assert world_exploration([{}, {"final_coverage": None}]) is None


def test_the_loaded_worlds_table_has_summary_csv_s_exploration_columns(
    explored, tmp_path, rooms, client, five_run_config
):
    """report.load's worlds table (what the study's table of cells reads) holds summary.csv's exploration means."""
    import pandas as pd

    from slamtrials.report.load import WORLD_COLUMNS, load_campaign

    assert set(EXPLORATION_CSV_COLUMNS) <= set(WORLD_COLUMNS)
    worlds = load_campaign(explored).worlds
    (csv_row,) = csv.DictReader((explored / "summary.csv").open())
    for column in EXPLORATION_CSV_COLUMNS:
        value = worlds[column].iloc[0]
        if csv_row[column] == "":
            assert pd.isna(value), column
        else:
            assert float(value) == float(csv_row[column]), column  # the CSV keeps every digit
    assert worlds["reached_99"].dtype == "Int64" and worlds["time_to_90_s_mean"].dtype == "float64"
    run_campaign(five_run_config(rooms[:1]), tmp_path / "c", scheduler=client, trial_fn=FakeTrial())
    assert load_campaign(tmp_path / "c").worlds[list(EXPLORATION_CSV_COLUMNS)].isna().all(axis=None)
