"""Which runs diverged: above a factor times the median."""

from __future__ import annotations

import numpy as np
import pytest

from slamtrials.errors import MetricError
from slamtrials.metric.divergence import divergence


def test_runs_far_above_the_median_are_diverged():
    d = divergence([0.05, 0.04, 0.06, 1.2, 0.05, 0.30, 0.05])
    assert d.threshold == pytest.approx(5 * 0.05)  # median of the seven is 0.05
    assert d.diverged.tolist() == [False, False, False, True, False, True, False]
    assert d.share == pytest.approx(2 / 7)


def test_a_factor_and_a_set_without_outliers():
    d = divergence(np.full(7, 0.1), factor=2.0)
    assert d.threshold == pytest.approx(0.2) and not d.diverged.any() and d.share == 0.0


@pytest.mark.parametrize(
    ("values", "factor", "match"), [([], 5.0, "no runs"), ([0.1, np.nan], 5.0, "run 1"), ([0.1, 0.2], 1.0, "above 1")]
)
def test_bad_input_is_refused(values, factor, match):
    with pytest.raises(MetricError, match=match):
        divergence(values, factor)
