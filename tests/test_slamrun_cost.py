"""SLAM over a recording records what it cost: ``slamtrials slam`` (slam.json) and ``slam --runs`` (runs.csv,
summary.json)."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from slamtrials.cost import COST_FIGURES, COST_KEY, RunCost
from slamtrials.metric import relations_between
from slamtrials.record import Trajectory
from slamtrials.repeat import RepeatSettings, repeat_slam, write_repeat_outputs
from slamtrials.sim import SimConfig, simulate_waypoints
from slamtrials.slamrun import run_slam, write_slam_outputs
from slamtrials.worlds import World


@pytest.fixture(scope="module")
def record():
    occupied = np.ones((60, 100), bool)
    occupied[10:50, 10:90] = False
    world = World(occupied, 0.05, name="box", start=np.array([1.0, 1.0, 0.0]))
    return simulate_waypoints(world, [[3.5, 1.0], [3.5, 1.9]], SimConfig.paper(), seed=1, max_time=30)


def test_slam_json_holds_the_run_s_cost(record, tmp_path):
    result = run_slam(record, "odometry", seed=1)
    assert result.cost is not None and 0.0 <= result.cost.slam_cpu_s <= result.cost.run_cpu_s
    write_slam_outputs(result, tmp_path / "out")
    doc = json.loads((tmp_path / "out" / "slam.json").read_text())
    assert RunCost.of(doc) == result.cost


def test_repeated_slam_reports_each_run_s_cost(record, tmp_path):
    from distributed import Client, LocalCluster

    truth = Trajectory(t=record.t, poses=record.truth)
    i = np.arange(0, len(record) - 10, 5)
    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        Client(cluster) as client,
    ):
        result = repeat_slam(
            record, relations_between(truth, i, i + 10), RepeatSettings(algorithm="odometry", runs=2), scheduler=client
        )
    assert all(run.cost is not None and run.cost.slam_cpu_s >= 0.0 for run in result.runs)
    write_repeat_outputs(result, tmp_path / "out")
    rows = list(csv.DictReader((tmp_path / "out" / "runs.csv").open()))
    assert len(rows) == 2 and all(float(row["slam_cpu_s"]) >= 0.0 for row in rows)
    assert set(COST_FIGURES) <= set(rows[0])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary[COST_KEY]["slam_cpu_s_mean"] == pytest.approx(
        np.mean([float(r["slam_cpu_s"]) for r in rows]), rel=1e-4
    )
