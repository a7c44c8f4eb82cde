"""Exploration measures from a coverage curve: thresholds, never reached, decimation, the JSON form."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from slamtrials.trial.exploration import (
    EXPLORATION_FORMAT,
    EXPLORATION_KEY,
    MAX_CURVE_POINTS,
    ExplorationMeasures,
    decimate,
    exploration_measures,
    first_reaching,
)


def test_a_threshold_met_exactly_at_a_sample_counts_there():
    t = [0.0, 5.0, 10.0, 15.0, 20.0]
    coverage = [0.0, 0.5, 0.9, 0.95, 0.99]
    distance = [0.0, 2.0, 4.5, 6.0, 8.0]
    found = exploration_measures(t, coverage, distance, "map_converged")
    assert (found.time_to_90_s, found.distance_to_90_m) == (10.0, 4.5)
    assert (found.time_to_99_s, found.distance_to_99_m) == (20.0, 8.0)
    assert found.final_coverage == 0.99
    assert found.termination_reason == "map_converged"
    assert found.curve_t == tuple(t) and found.curve_coverage == tuple(coverage)
    assert found.reached(0.90) and found.reached(0.99)


def test_just_below_a_threshold_is_not_reaching_it():
    found = exploration_measures([0.0, 1.0, 2.0], [0.2, 0.8999999, 0.9], [0.0, 1.0, 3.0], "no_frontiers")
    assert found.time_to_90_s == 2.0 and found.distance_to_90_m == 3.0


def test_never_reached_is_none():
    found = exploration_measures([0.0, 10.0, 20.0], [0.1, 0.6, 0.95], [0.0, 3.0, 7.0], "time_cap")
    assert found.time_to_90_s == 20.0
    assert found.time_to_99_s is None and found.distance_to_99_m is None
    assert not found.reached(0.99)
    none = exploration_measures([0.0, 10.0], [0.1, 0.2], [0.0, 1.0], "time_cap")
    assert none.time_to_90_s is None and none.distance_to_90_m is None
    assert none.time_to(0.90) is None and none.distance_to(0.99) is None


def test_first_reaching():
    assert first_reaching(np.array([0.1, 0.95, 0.9, 1.0]), 0.9) == 1
    assert first_reaching(np.array([0.1, 0.2]), 0.9) is None
    assert first_reaching(np.array([]), 0.9) is None


def test_decimation_keeps_first_last_and_the_crossings():
    count = 5000
    t = np.arange(count) * 0.5
    coverage = np.minimum(1.0, np.arange(count) / 3000.0)
    coverage[1234] = 0.9  # the 90 % crossing falls between evenly spread samples
    coverage[:1234] = np.minimum(coverage[:1234], 0.899)
    found = exploration_measures(t, coverage, t * 0.3, "no_frontiers")
    assert len(found.curve_t) <= MAX_CURVE_POINTS
    assert len(found.curve_t) == len(found.curve_coverage)
    assert found.curve_t[0] == 0.0 and found.curve_t[-1] == t[-1]
    assert found.time_to_90_s in found.curve_t and found.time_to_99_s in found.curve_t
    assert found.time_to_90_s == t[1234]
    assert found.curve_coverage[-1] == found.final_coverage == 1.0
    assert list(found.curve_t) == sorted(set(found.curve_t))  # increasing, no repeats


@pytest.mark.parametrize("count", [1, 2, 199, 200, 201, 1000, 10_007])
@pytest.mark.parametrize("keep", [(), (1,), (100, 101, 102), (0, 7)])
def test_decimate(count, keep):
    chosen = decimate(count, keep, 200)
    assert chosen.size == min(count, 200)
    assert chosen[0] == 0 and chosen[-1] == count - 1
    assert np.all(np.diff(chosen) > 0)
    assert all(k in chosen for k in keep if k < count)


def test_decimate_refuses_too_few_points():
    with pytest.raises(ValueError, match="cannot hold"):
        decimate(100, (10, 20, 30), 3)


def test_shapes_must_agree():
    with pytest.raises(ValueError, match="alike"):
        exploration_measures([0.0, 1.0], [0.0], [0.0, 1.0], "x")


def test_the_json_form_round_trips():
    found = exploration_measures([0.0, 1.0, 2.0], [0.0, 0.95, 0.999], [0.0, 1.5, 2.5], "no_frontiers")
    doc = json.loads(json.dumps(found.to_dict()))
    assert doc["format"] == EXPLORATION_FORMAT
    assert doc["time_to_99_s"] == 2.0 and doc["curve"]["coverage"] == [0.0, 0.95, 0.999]
    assert ExplorationMeasures.from_dict(doc) == found
    assert ExplorationMeasures.of({EXPLORATION_KEY: doc}) == found
    never = exploration_measures([0.0], [0.5], [0.0], "time_cap").to_dict()
    assert never["time_to_90_s"] is None
    assert ExplorationMeasures.from_dict(json.loads(json.dumps(never))).time_to_90_s is None


def test_a_run_json_of_an_earlier_version_has_none():
    assert ExplorationMeasures.of({"trial": {"termination_reason": "map_converged"}}) is None
    partial = ExplorationMeasures.from_dict({"time_to_90_s": 3.0})
    assert partial.time_to_90_s == 3.0 and partial.time_to_99_s is None
    assert math.isnan(partial.final_coverage) and partial.termination_reason == "unknown"
    assert partial.curve_t == ()
