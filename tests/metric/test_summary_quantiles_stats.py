"""Summary as the Freiburg program prints it, critical values, and per-environment statistics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamtrials.errors import MetricError
from slamtrials.metric import critical_value, environment_stats, summarize
from slamtrials.metric.summary import SUMMARY_HEADER


def test_summary_known_answer_uses_the_sample_std():
    s = summarize([0.1, 0.2, 0.3, 0.6])
    assert s.n == 4
    assert s.mean == pytest.approx(0.3)
    assert s.std == pytest.approx(math.sqrt((0.04 + 0.01 + 0.0 + 0.09) / 3))  # divisor N - 1
    assert (s.min, s.max) == (0.1, 0.6)
    assert s.as_tuple() == (s.mean, s.std, s.min, s.max, 4)
    assert SUMMARY_HEADER == "Mean, Std, Min, Max, NumMeasures"


def test_summary_of_one_and_of_no_errors():
    one = summarize([0.5])
    assert (one.mean, one.min, one.max, one.n) == (0.5, 0.5, 0.5, 1) and math.isnan(one.std)
    none = summarize([])
    assert none.n == 0 and all(math.isnan(v) for v in (none.mean, none.std, none.min, none.max))


def test_critical_values():
    assert critical_value(0.99) == pytest.approx(2.5758, abs=1e-4)  # the default: two-sided normal
    assert critical_value(0.95) == pytest.approx(1.95996, abs=1e-5)
    assert critical_value(0.95, sides=1) == pytest.approx(1.64485, abs=1e-5)
    # the seed system's one-sided Student t with a 500-pair pilot (its comment says 2.58)
    assert critical_value(0.99, distribution="t", dof=499, sides=1) == pytest.approx(2.334, abs=1e-3)
    assert critical_value(0.95, distribution="t", dof=3) == pytest.approx(3.1824, abs=1e-4)


@pytest.mark.parametrize(
    ("kwargs", "problem"),
    [
        ({"confidence": 1.0}, "strictly between 0 and 1"),
        ({"confidence": 0.9, "sides": 3}, "sides"),
        ({"confidence": 0.9, "distribution": "t"}, "degrees of freedom"),
        ({"confidence": 0.9, "distribution": "cauchy"}, "unknown distribution"),
    ],
)
def test_critical_value_refuses_bad_settings(kwargs, problem):
    with pytest.raises(MetricError, match=problem):
        critical_value(**kwargs)


def test_environment_stats_population_and_sample_forms():
    s = environment_stats([1.0, 2.0, 3.0, 4.0], confidence=0.95, distribution="normal")
    assert s.n == 4 and s.mean == 2.5
    assert s.std_population == pytest.approx(math.sqrt(1.25))  # the paper's Definition III.3 (divisor |R_E|)
    assert s.std_sample == pytest.approx(math.sqrt(5 / 3))
    assert s.half_width == pytest.approx(1.959964 * math.sqrt(5 / 3) / 2, rel=1e-6)
    assert (s.ci_low, s.ci_high) == pytest.approx((2.5 - s.half_width, 2.5 + s.half_width))
    t = environment_stats([1.0, 2.0, 3.0, 4.0], confidence=0.95)  # Student t by default
    assert t.half_width == pytest.approx(3.182446 * math.sqrt(5 / 3) / 2, rel=1e-6)


def test_environment_stats_of_one_run_and_bad_input():
    one = environment_stats([0.3])
    assert one.mean == 0.3 and one.std_population == 0.0 and math.isnan(one.std_sample) and math.isnan(one.ci_low)
    with pytest.raises(MetricError, match="empty"):
        environment_stats([])
    with pytest.raises(MetricError, match="run 1") as info:
        environment_stats([0.1, np.nan])
    assert info.value.index == 1
