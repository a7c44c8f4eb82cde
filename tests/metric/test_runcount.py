"""The run-count rule of the paper's Section III-C: known answers and the iterative loop."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.errors import MetricError
from slamtrials.metric import replay_run_count, runs_needed


def test_known_answer():
    """eps_t = 1..10 m: s^2 = 55/6; z(99 %) = 2.5758, z^2 s^2 / 1^2 = 6.6349 * 9.1667 = 60.82 -> 61 runs."""
    eps_t = np.arange(1.0, 11.0)
    eps_r = np.full(10, 0.05)  # no spread: N_r = 0
    rc = runs_needed(eps_t, eps_r, margin_t=1.0, margin_r=0.01, distribution="normal")  # the paper's quantile
    assert rc.std_t == pytest.approx(math.sqrt(55 / 6))
    assert rc.std_r == 0.0
    assert (rc.needed_t, rc.needed_r, rc.needed, rc.done) == (61, 0, 61, 10)
    assert not rc.enough and not rc.capped
    assert rc.critical == pytest.approx(2.5758, abs=1e-4)


def test_max_of_translation_and_rotation_and_the_floor_of_min_runs():
    eps_t = np.array([0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1])
    eps_r = np.array([0.0, 0.2] * 5)  # s^2 = 10/9 * 0.01
    rc = runs_needed(eps_t, eps_r, margin_t=0.01, margin_r=0.05, confidence=0.95, distribution="normal")
    assert rc.needed_r == math.ceil(1.959964**2 * (0.01 * 10 / 9) / 0.05**2)  # 17.07 -> 18
    assert rc.needed == 18 and rc.needed_t == 0
    small = runs_needed(eps_t, eps_t, margin_t=0.01, margin_r=0.01)  # no spread at all: still 10 runs
    assert small.needed == 10 and small.enough


def test_before_min_runs_the_answer_is_min_runs():
    rc = runs_needed([0.1, 0.5, 0.9], [0.0, 0.1, 0.2], margin_t=0.01, margin_r=0.01)
    assert rc.needed == 10 and not rc.enough and math.isnan(rc.std_t)


def test_student_t_uses_runs_minus_one_degrees_of_freedom():
    eps = np.arange(1.0, 11.0)
    rc = runs_needed(eps, eps, margin_t=1.0, margin_r=1.0, distribution="t")
    assert rc.critical == pytest.approx(3.2498, abs=1e-4)  # t(0.995, 9)


def test_cap_is_reported():
    eps_t = np.arange(1.0, 11.0)
    rc = runs_needed(eps_t, eps_t, margin_t=1.0, margin_r=1.0, max_runs=30)
    assert rc.needed == 30 and rc.capped and not rc.enough
    eps_30 = np.resize(eps_t, 30)
    final = runs_needed(eps_30, eps_30, margin_t=1.0, margin_r=1.0, max_runs=30)
    assert final.enough and final.capped


def test_replay_stops_when_the_new_estimate_is_not_larger_than_the_runs_done():
    """Alternating errors +-1 around a mean: 10 runs ask for 18 (s^2 = 10/9); 18 runs ask for 17 (s^2 = 18/17): stop at 18."""
    eps_t = np.array([0.0, 2.0] * 50)
    eps_r = np.zeros(100)
    paper = {"margin_t": 0.5, "margin_r": 0.1, "confidence": 0.95, "distribution": "normal"}
    first = runs_needed(eps_t[:10], eps_r[:10], **paper)
    assert first.needed == 18
    final = replay_run_count(eps_t, eps_r, **paper)
    assert final is not None and final.done == 18 and final.needed == 17 and final.enough
    assert replay_run_count(eps_t[:15], eps_r[:15], **paper) is None


def test_the_default_quantile_is_student_t_with_runs_minus_one_degrees_of_freedom():
    """10 runs, s^2 = 10/9 around 1: t(0.975, 9) = 2.2622 gives ceil(2.2622^2 * 10/9 / 0.25) = 23 runs (normal: 18)."""
    eps_t = np.array([0.0, 2.0] * 5)
    rc = runs_needed(eps_t, np.zeros(10), margin_t=0.5, margin_r=0.1, confidence=0.95)
    assert rc.critical == pytest.approx(2.2622, abs=1e-4) and rc.needed == 23


def test_bad_input():
    with pytest.raises(MetricError, match="eps_t has 2 runs but eps_r has 3"):
        runs_needed([0.1, 0.2], [0.1, 0.2, 0.3], margin_t=0.1, margin_r=0.1)
    with pytest.raises(MetricError, match="run 1 has a non-finite"):
        runs_needed([0.1, math.inf], [0.1, 0.2], margin_t=0.1, margin_r=0.1)
    with pytest.raises(MetricError, match="margin"):
        runs_needed(np.ones(10), np.ones(10), margin_t=0.0, margin_r=0.1)


def test_bad_settings():
    with pytest.raises(MetricError, match="min_runs must be at least 2"):
        runs_needed(np.ones(10), np.ones(10), margin_t=0.1, margin_r=0.1, min_runs=1)
    with pytest.raises(MetricError, match="max_runs"):
        runs_needed(np.ones(10), np.ones(10), margin_t=0.1, margin_r=0.1, max_runs=5)
