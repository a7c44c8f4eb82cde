"""Per-world tables (the paper's Table I) against hand computations, and the shared outlier rule."""

from __future__ import annotations

import io
import math

import numpy as np
import pandas as pd
import pytest
from matplotlib import cbook
from scipy import stats

from slamtrials.report.tables import (
    outlier_mask,
    paper_table,
    world_outliers,
    world_summary,
)

Z99 = stats.norm.ppf(0.995)  # 2.5758...


def _runs() -> pd.DataFrame:
    # Worlds out of order on purpose; "b" has a high outlier in eps_t, "c" a single run.
    return pd.DataFrame(
        {
            "world": ["b", "a", "b", "a", "b", "a", "b", "a", "b", "c"],
            "run": [0, 0, 1, 1, 2, 2, 3, 3, 4, 0],
            "seed": range(10),
            "eps_t": [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 100.0, 0.5],
            "eps_r": [0.1, 0.2, 0.1, 0.2, 0.1, 0.2, 0.1, 0.2, 0.1, 0.05],
            "termination": ["done"] * 10,
            "extra": list("abcdefghij"),
        }
    )


def test_world_summary_matches_hand_computation_and_is_sorted_by_world() -> None:
    table = world_summary(_runs(), confidence=0.99, distribution="normal")  # the paper's quantile
    assert list(table["world"]) == ["a", "b", "c"]
    assert list(table["runs"]) == [4, 5, 1]
    a = table.iloc[0]
    # a: eps_t = 1, 2, 3, 4 -> mean 2.5, sample variance 5/3, population variance 5/4.
    assert a["eps_t_mean"] == pytest.approx(2.5)
    assert a["eps_t_std"] == pytest.approx(math.sqrt(5.0 / 3.0))
    assert a["eps_t_std_population"] == pytest.approx(math.sqrt(1.25))
    half = Z99 * math.sqrt(5.0 / 3.0) / 2.0
    assert a["eps_t_half_width"] == pytest.approx(half)
    assert (a["eps_t_ci_low"], a["eps_t_ci_high"]) == pytest.approx((2.5 - half, 2.5 + half))
    assert (a["eps_t_min"], a["eps_t_max"]) == (1.0, 4.0)
    # a: eps_r constant 0.2 -> zero spread, a degenerate interval.
    assert a["eps_r_mean"] == pytest.approx(0.2) and a["eps_r_std"] == pytest.approx(0.0)
    assert a["eps_r_ci_low"] == pytest.approx(0.2) and a["eps_r_ci_high"] == pytest.approx(0.2)
    assert a["confidence"] == 0.99


def test_outlier_count_follows_tukey_fences() -> None:
    table = world_summary(_runs()).set_index("world")
    # b: 1, 2, 3, 4, 100 -> Q1 = 2, Q3 = 4, fences -1 and 7: only 100 is out.
    assert table.loc["b", "eps_t_outliers"] == 1
    assert table.loc["a", "eps_t_outliers"] == 0
    assert table.loc["b", "eps_r_outliers"] == 0
    assert table.loc["c", "eps_t_outliers"] == 0


def test_single_run_world_has_undefined_spread() -> None:
    c = world_summary(_runs()).set_index("world").loc["c"]
    assert c["eps_t_mean"] == 0.5 and c["eps_t_std_population"] == 0.0
    assert math.isnan(c["eps_t_std"]) and math.isnan(c["eps_t_ci_low"]) and math.isnan(c["eps_t_ci_high"])


def test_outlier_mask_boundaries_and_agreement_with_matplotlib_boxplot() -> None:
    # Ten 2s and ten 4s fix Q1 = 2 and Q3 = 4 whatever the probe: fences -1 and 7, a value on a fence is in.
    base = [2.0] * 10 + [4.0] * 10
    assert outlier_mask(base + [7.0]).sum() == 0
    assert outlier_mask(base + [-1.0]).sum() == 0
    assert outlier_mask(base + [7.001]).tolist()[-1]
    assert outlier_mask(base + [-1.001]).tolist()[-1]
    assert outlier_mask([-10.0, 1, 2, 3, 4, 5]).tolist() == [True, False, False, False, False, False]
    rng = np.random.default_rng(3)
    for _ in range(20):
        w = rng.standard_t(2, size=int(rng.integers(3, 40)))
        fliers = cbook.boxplot_stats(w, whis=1.5)[0]["fliers"]
        assert sorted(w[outlier_mask(w)]) == sorted(fliers)
    assert outlier_mask([]).shape == (0,)


def test_world_outliers_is_aligned_with_the_rows() -> None:
    runs = _runs()
    runs.index = range(100, 110)
    flags = world_outliers(runs, "eps_t")
    assert list(flags.index) == list(runs.index)
    assert flags[flags].index.tolist() == [108]  # the 100.0 of world b


def test_missing_column_and_non_finite_value_are_named() -> None:
    with pytest.raises(ValueError, match="eps_r"):
        world_summary(_runs().drop(columns="eps_r"))
    with pytest.raises(ValueError, match="'run'"):
        world_summary(_runs().drop(columns="run"))
    bad = _runs()
    bad.loc[3, "eps_t"] = np.nan
    with pytest.raises(ValueError, match=r"world 'a' run 1 has a non-finite eps_t"):
        world_summary(bad)


def test_csv_round_trip_and_paper_layout() -> None:
    table = world_summary(_runs())
    back = pd.read_csv(io.StringIO(table.to_csv(index=False)))
    assert list(back.columns) == list(table.columns)
    assert np.allclose(back["eps_t_mean"], table["eps_t_mean"])
    printed = paper_table(table, "eps_t")
    assert list(printed.index) == ["average", "std dev"] and list(printed.columns) == ["a", "b", "c"]
    assert printed.loc["average", "a"] == pytest.approx(2.5)
    assert paper_table(table, "eps_t", population=True).loc["std dev", "a"] == pytest.approx(math.sqrt(1.25))


@pytest.mark.parametrize(
    ("share", "text"),
    [
        (0.00019, "0.019 %"),
        (0.0037, "0.37 %"),
        (0.05, "5.0 %"),
        (0.123, "12 %"),
        (1.5, "150 %"),
        (0.0, "0 %"),
        (8.9e-38, "< 0.001 %"),
    ],
)
def test_a_metric_share_keeps_two_significant_digits(share, text):
    """A share of 0.019 % must not read 0.0 % in the report while the CLI says 0.019 %."""
    from slamtrials.report.tables import share_percent

    assert share_percent(share) == text
