"""A trial records what it cost (run.json ``cost``), and measuring it changes nothing of the run."""

from __future__ import annotations

import json

import numpy as np
import pytest

import slamtrials.trial.run as trial_run
from slamtrials.cost import COST_KEY, IN_PROCESS, RunCost
from slamtrials.costmeter import ResidentMemory
from slamtrials.io.runfolder import read_run, write_run
from slamtrials.trial import TrialConfig, TrialSummary, run_trial
from slamtrials.worlds import World

RES = 0.05


def _room() -> World:
    """A 6 m x 4 m room."""
    height, width = int(4.0 / RES) + 2, int(6.0 / RES) + 2
    occupied = np.zeros((height, width), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    return World(occupied, RES, name="room", start=np.array([1.5, 2.0, 0.0]))


CONFIG = TrialConfig.from_dict({"sim": {"profile": "paper"}, "termination": {"small_period": 60.0, "max_time": 15.0}})


class NoMeter:
    """A meter that measures nothing: the trial as it ran before costs were measured."""

    def __init__(self, *, memory: bool = True) -> None:
        pass

    def enter(self) -> None:
        return None

    def leave(self, mark: object, *, update_seconds: float | None = None) -> None:
        pass

    def finish(self, child: object = None, *, in_child: bool = False) -> RunCost:
        return RunCost(None, None, None, None)


@pytest.fixture(scope="module")
def record():
    return run_trial(_room(), CONFIG, seed=3)


def test_the_trial_records_a_plausible_cost(record):
    cost = RunCost.of(record.metadata)
    summary = TrialSummary.of(record)
    assert cost is not None and summary is not None and cost.slam_process == IN_PROCESS
    assert 0.0 <= cost.slam_cpu_s <= cost.run_cpu_s
    assert cost.run_cpu_s <= summary.wall_time_s * 1.5 + 0.5  # the thread's CPU time, not more than it ran
    assert 1 <= cost.updates_timed <= summary.slam_updates
    assert 0.0 < cost.update_ms_median <= cost.update_ms_p90
    if ResidentMemory.open() is not None:
        assert cost.slam_peak_mib >= 0.0 and cost.run_peak_mib > 50.0  # the Python runtime alone holds more


def test_measuring_the_cost_changes_nothing_of_the_run(record, monkeypatch):
    monkeypatch.setattr(trial_run, "CostMeter", NoMeter)
    unmeasured = run_trial(_room(), CONFIG, seed=3)
    for name in ("t", "scans", "odometry", "truth", "stalled", "estimate", "online"):
        assert np.array_equal(getattr(unmeasured, name), getattr(record, name)), name
    assert np.array_equal(unmeasured.map.grid, record.map.grid)
    assert _results(unmeasured.metadata["trial"]) == _results(record.metadata["trial"])


def _results(trial: dict) -> dict:
    """A trial's summary without its wall-clock timings."""
    timings = ("wall_time_s", "realtime_factor", "slam_seconds")
    kept = {k: v for k, v in trial.items() if k not in timings}
    kept["explorer"] = {k: v for k, v in trial["explorer"].items() if "seconds" not in k}
    return kept


def test_the_run_folder_keeps_the_cost_and_an_old_one_without_it_still_loads(record, tmp_path):
    write_run(tmp_path / "run", record)
    doc = json.loads((tmp_path / "run" / "run.json").read_text())
    assert doc[COST_KEY]["format"] == "slamtrials-cost/1"
    assert RunCost.of(read_run(tmp_path / "run").metadata) == RunCost.of(record.metadata)
    del doc[COST_KEY]  # as a version before costs wrote it
    (tmp_path / "run" / "run.json").write_text(json.dumps(doc))
    old = read_run(tmp_path / "run")
    assert RunCost.of(old.metadata) is None and TrialSummary.of(old) == TrialSummary.of(record)
