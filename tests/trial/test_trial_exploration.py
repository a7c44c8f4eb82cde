"""A trial records its exploration measures (run.json ``exploration``); an old run.json without them loads."""

from __future__ import annotations

import json

import numpy as np
import pytest

from slamtrials.io.runfolder import read_run, write_run
from slamtrials.trial import TrialConfig, TrialSummary, run_trial
from slamtrials.trial.exploration import EXPLORATION_FORMAT, EXPLORATION_KEY, MAX_CURVE_POINTS, ExplorationMeasures
from slamtrials.worlds import World

RES = 0.05


def _two_rooms() -> World:
    """A 6 m x 4 m box split by a wall with a 1 m door; the robot starts in the left room."""
    height, width = int(4.0 / RES) + 2, int(6.0 / RES) + 2
    occupied = np.zeros((height, width), dtype=bool)
    occupied[:3, :] = occupied[-3:, :] = occupied[:, :3] = occupied[:, -3:] = True
    wall = width // 2
    occupied[:, wall : wall + 3] = True
    occupied[height // 2 - 10 : height // 2 + 10, wall : wall + 3] = False
    return World(occupied, RES, name="two-rooms", start=np.array([1.0, 2.0, 0.0]))


CONFIG = TrialConfig.from_dict({"sim": {"profile": "paper"}, "termination": {"small_period": 60.0, "max_time": 400.0}})


@pytest.fixture(scope="module")
def record():
    return run_trial(_two_rooms(), CONFIG, seed=5)


@pytest.mark.slow
def test_the_trial_records_its_exploration_measures(record):
    found = ExplorationMeasures.of(record.metadata)
    summary = TrialSummary.of(record)
    assert found is not None and summary is not None
    assert found.termination_reason == summary.termination_reason
    assert found.final_coverage == summary.mapped_fraction  # the same cells, the same final map
    t, coverage = np.array(found.curve_t), np.array(found.curve_coverage)
    assert 2 <= t.size <= MAX_CURVE_POINTS and t.size == coverage.size
    assert t[0] == 0.0 and t[-1] == pytest.approx(summary.duration_s, abs=1e-3)
    assert np.all(np.diff(t) > 0) and np.all(np.diff(coverage) >= 0)
    assert coverage[-1] == pytest.approx(found.final_coverage, abs=1e-5)
    assert 0.0 <= coverage[0] < 0.9 <= found.final_coverage
    # the thresholds: the first sample at or above them, at its time and distance along the true path
    assert found.time_to_90_s is not None and found.time_to_90_s in found.curve_t
    assert coverage[list(found.curve_t).index(found.time_to_90_s)] >= 0.9
    assert coverage[: list(found.curve_t).index(found.time_to_90_s)].max() < 0.9
    assert 0.0 < found.distance_to_90_m <= summary.distance_m + 1e-9
    if found.time_to_99_s is not None:
        assert found.time_to_90_s <= found.time_to_99_s and found.distance_to_90_m <= found.distance_to_99_m
    else:
        assert found.final_coverage < 0.99 and found.distance_to_99_m is None


@pytest.mark.slow
def test_run_json_holds_them_and_an_old_one_without_them_still_loads(record, tmp_path):
    write_run(tmp_path / "run", record)
    doc = json.loads((tmp_path / "run" / "run.json").read_text())
    stored = doc[EXPLORATION_KEY]
    assert stored["format"] == EXPLORATION_FORMAT
    assert set(stored) >= {
        "time_to_90_s",
        "distance_to_90_m",
        "time_to_99_s",
        "distance_to_99_m",
        "final_coverage",
        "termination_reason",
        "curve",
    }
    assert set(stored["curve"]) == {"t", "coverage"}
    assert ExplorationMeasures.of(read_run(tmp_path / "run").metadata) == ExplorationMeasures.of(record.metadata)
    del doc[EXPLORATION_KEY]  # as a version before exploration measures wrote it
    (tmp_path / "run" / "run.json").write_text(json.dumps(doc))
    old = read_run(tmp_path / "run")
    assert ExplorationMeasures.of(old.metadata) is None and TrialSummary.of(old) == TrialSummary.of(record)
