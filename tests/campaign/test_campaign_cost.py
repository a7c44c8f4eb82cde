"""What runs cost, kept by a campaign: the catalog's details, summary.csv's means, replays' own cost, and
catalogs of runs that recorded none."""

from __future__ import annotations

import csv
import json

import pytest

from slamtrials.campaign import load_summary, run_campaign
from slamtrials.campaign.costsummary import COST_CSV_COLUMNS, world_cost
from slamtrials.campaign.replay import replay_campaign
from slamtrials.campaign.store import CampaignStore
from slamtrials.campaign.testing import FakeTrial
from slamtrials.cost import COST_FIGURES, IN_PROCESS, RunCost

COST = RunCost(2.0, 40.0, 3.0, 250.0, 20.0, 30.0, updates_timed=5)


@pytest.fixture(scope="module")
def costed(tmp_path_factory, rooms, client, five_run_config):
    folder = tmp_path_factory.mktemp("costed") / "c"
    run_campaign(five_run_config(rooms[:1]), folder, scheduler=client, trial_fn=FakeTrial(cost=COST))
    return folder


def test_the_catalog_and_summary_csv_keep_the_runs_cost(costed):
    with CampaignStore.open(costed) as store:
        details = [json.loads(run.details) for run in store.runs()]
    assert len(details) == 5 and all(d["slam_cpu_s"] == 2.0 and d["update_ms_p90"] == 30.0 for d in details)
    (row,) = load_summary(costed)
    assert row.cost is not None and row.cost.runs == 5
    assert row.cost.means() == (2.0, 40.0, 3.0, 250.0, 20.0, 30.0)
    (csv_row,) = csv.DictReader((costed / "summary.csv").open())
    assert [float(csv_row[c]) for c in COST_CSV_COLUMNS] == [2.0, 40.0, 3.0, 250.0, 20.0, 30.0]


def test_runs_without_cost_leave_the_cells_empty(tmp_path, rooms, client, five_run_config):
    run_campaign(five_run_config(rooms[:1]), tmp_path / "c", scheduler=client, trial_fn=FakeTrial())
    (row,) = load_summary(tmp_path / "c")
    assert row.cost is None
    (csv_row,) = csv.DictReader((tmp_path / "c" / "summary.csv").open())
    assert all(csv_row[c] == "" for c in COST_CSV_COLUMNS)


def test_a_world_cost_is_the_mean_over_the_runs_that_recorded_each_figure():
    cost = world_cost([{"slam_cpu_s": 1.0, "slam_peak_mib": None}, {"slam_cpu_s": 3.0, "slam_peak_mib": 8.0}, {}])
    assert cost is not None and cost.runs == 2 and cost.slam_cpu_s == 2.0 and cost.slam_peak_mib == 8.0
    assert cost.update_ms_median is None
    assert world_cost([{"eps_t": 0.1}]) is None


def test_a_replay_records_its_own_cost_not_the_source_trial_s(costed, tmp_path, client):
    replay_campaign(costed, tmp_path / "r", scheduler=client)
    with CampaignStore.open(tmp_path / "r") as store:
        runs = store.runs()
    for run in runs:
        doc = json.loads((tmp_path / "r" / run.folder / "run.json").read_text())
        cost = RunCost.of(doc)
        assert cost is not None and cost.slam_process == IN_PROCESS and cost.slam_cpu_s != COST.slam_cpu_s
        assert 0.0 <= cost.slam_cpu_s <= cost.run_cpu_s
        assert {k: json.loads(run.details)[k] for k in COST_FIGURES} == cost.figures()
    (row,) = load_summary(tmp_path / "r")
    assert row.cost is not None and row.cost.runs == len(runs)
