"""RunCost: its JSON form, what an old run.json without one reads as, and the update-time statistics."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from slamtrials.cost import COST_FIGURES, COST_KEY, IN_PROCESS, RunCost, update_times_ms


def test_the_json_form_round_trips_and_names_every_figure():
    cost = RunCost(6.4, 52.0, 8.6, 280.0, 25.0, 41.0, updates_timed=295)
    doc = json.loads(json.dumps(cost.to_dict()))
    assert doc["format"] == "slamtrials-cost/1" and set(COST_FIGURES) <= set(doc)
    assert RunCost.from_dict(doc) == cost
    assert RunCost.of({COST_KEY: doc}) == cost
    assert cost.figures() == dict(zip(COST_FIGURES, (6.4, 52.0, 8.6, 280.0, 25.0, 41.0)))


def test_a_run_json_without_cost_or_with_missing_figures_reads_as_not_measured():
    assert RunCost.of({"trial": {}, "seed": 1}) is None  # a run.json of an earlier version
    assert RunCost.of({COST_KEY: "garbage"}) is None
    partial = RunCost.from_dict({"slam_cpu_s": 1.5, "slam_peak_mib": None, "run_cpu_s": "x", "run_peak_mib": math.nan})
    assert partial.slam_cpu_s == 1.5
    assert partial.slam_peak_mib is None and partial.run_cpu_s is None and partial.run_peak_mib is None
    assert partial.update_ms_median is None and partial.updates_timed == 0 and partial.slam_process == IN_PROCESS


def test_update_times_are_the_median_and_90th_percentile_in_ms():
    median, p90 = update_times_ms([0.001 * k for k in range(1, 11)])  # 1 .. 10 ms
    assert median == pytest.approx(5.5) and p90 == pytest.approx(9.1)
    assert update_times_ms([]) == (None, None)
    assert update_times_ms(np.array([np.nan, 0.002])) == (pytest.approx(2.0), pytest.approx(2.0))
