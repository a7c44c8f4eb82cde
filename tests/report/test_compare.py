"""Comparison of two campaigns: Welch statistics against scipy and hand computations, corrections, verdicts,
the sign test, and the paper's Fig. 6 trap."""

from __future__ import annotations

import math
from itertools import product

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from slamtrials.report.compare import (
    A_BETTER,
    B_BETTER,
    NO_DIFFERENCE,
    TOO_FEW,
    adjust_pvalues,
    compare_campaigns,
    paired_reversal,
    reversal,
    sign_test,
    welch,
    world_pair_traps,
)


def _frame(samples: dict[str, list[float]], first_run: int = 0) -> pd.DataFrame:
    rows = []
    for world, values in samples.items():
        for k, v in enumerate(values):
            rows.append(
                {
                    "world": world,
                    "run": first_run + k,
                    "seed": k,
                    "eps_t": v,
                    "eps_r": v / 10.0,
                    "termination": "done",
                    "mapped": 1.0,
                }
            )
    return pd.DataFrame(rows)


def test_welch_matches_hand_computation() -> None:
    a, b = [1.0, 2.0, 3.0, 4.0], [2.0, 4.0, 6.0, 8.0, 10.0]
    va, vb = (5.0 / 3.0) / 4.0, 10.0 / 5.0  # s^2 / n of each side
    se = math.sqrt(va + vb)
    dof = (va + vb) ** 2 / (va**2 / 3.0 + vb**2 / 4.0)
    w = welch(a, b, confidence=0.95)
    assert w.difference == pytest.approx(6.0 - 2.5)
    assert w.se == pytest.approx(se)
    assert w.dof == pytest.approx(dof) and w.dof == pytest.approx(5.5208, abs=1e-4)
    assert w.t == pytest.approx(3.5 / se)
    q = stats.t.ppf(0.975, dof)
    assert (w.ci_low, w.ci_high) == pytest.approx((3.5 - q * se, 3.5 + q * se))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_welch_matches_scipy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a = rng.normal(0.3, 0.05, size=int(rng.integers(5, 30)))
    b = rng.normal(0.32, 0.09, size=int(rng.integers(5, 30)))
    ref = stats.ttest_ind(b, a, equal_var=False)
    w = welch(a, b, confidence=0.99)
    assert w.t == pytest.approx(ref.statistic)
    assert w.p == pytest.approx(ref.pvalue)
    assert w.dof == pytest.approx(ref.df)
    ci = ref.confidence_interval(confidence_level=0.99)
    assert (w.ci_low, w.ci_high) == pytest.approx((ci.low, ci.high))


def test_welch_degenerate_cases() -> None:
    same = welch([1.0, 1.0], [1.0, 1.0])
    assert same.p == 1.0 and same.t == 0.0
    apart = welch([1.0, 1.0], [2.0, 2.0])
    assert apart.p == 0.0 and apart.t == math.inf
    one = welch([1.0], [2.0, 3.0])
    assert one.difference == pytest.approx(1.5) and math.isnan(one.p) and math.isnan(one.ci_low)


def test_holm_and_benjamini_hochberg_by_hand() -> None:
    p = [0.01, 0.04, 0.03, 0.005]
    # Holm: sorted 0.005*4 = 0.02, 0.01*3 = 0.03, 0.03*2 = 0.06, 0.04*1 = 0.04 -> running max 0.06.
    assert adjust_pvalues(p, "holm") == pytest.approx([0.03, 0.06, 0.06, 0.02])
    # BH: sorted 0.005*4/1 = 0.02, 0.01*4/2 = 0.02, 0.03*4/3 = 0.04, 0.04*4/4 = 0.04 -> running min from the top.
    assert adjust_pvalues(p, "bh") == pytest.approx([0.02, 0.04, 0.04, 0.02])
    assert adjust_pvalues(p, "none") == pytest.approx(p)
    # NaN stays NaN and is not counted: m = 2.
    out = adjust_pvalues([0.01, math.nan, 0.04], "holm")
    assert out[0] == pytest.approx(0.02) and math.isnan(out[1]) and out[2] == pytest.approx(0.04)
    assert adjust_pvalues([0.4, 0.6], "holm") == pytest.approx([0.8, 0.8])
    assert adjust_pvalues([0.6, 0.7, 0.9], "holm").max() <= 1.0
    with pytest.raises(ValueError, match="correction"):
        adjust_pvalues(p, "bonferroni")


def test_sign_test_by_hand() -> None:
    assert sign_test(6, 0) == pytest.approx(2 / 64)
    assert sign_test(4, 1) == pytest.approx(2 * (1 + 5) / 32)
    assert sign_test(0, 0) == 1.0


def test_reversal_counts_pairs_like_brute_force() -> None:
    rng = np.random.default_rng(5)
    for _ in range(20):
        x = np.round(rng.normal(0.0, 1.0, int(rng.integers(1, 12))), 1)  # rounding makes ties
        y = np.round(rng.normal(0.8, 1.0, int(rng.integers(1, 12))), 1)
        if x.mean() >= y.mean():
            x, y = y, x
        if x.mean() == y.mean():
            continue
        r = reversal(x, y)
        brute = sum(xi > yj for xi, yj in product(x, y)) / (len(x) * len(y))
        assert r.fraction == pytest.approx(brute)
        assert r.reversed_by == pytest.approx(x.max() - y.min())
        assert x[r.i_low] == x.max() and y[r.i_high] == y.min()


def test_compare_campaigns_verdicts_pvalues_and_corrections() -> None:
    rng = np.random.default_rng(11)
    samples_a = {w: list(rng.normal(0.30, 0.02, 15)) for w in ("better", "same", "worse", "only_a")}
    samples_b = {
        "better": list(rng.normal(0.20, 0.02, 12)),
        "same": list(np.array(samples_a["same"][:10]) + 0.001),
        "worse": list(rng.normal(0.45, 0.03, 14)),
        "only_b": [0.1, 0.2],
    }
    a, b = _frame(samples_a), _frame(samples_b)
    c = compare_campaigns(a, b, alpha=0.05, labels=("gmapping", "karto"))
    assert c.only_a == ("only_a",) and c.only_b == ("only_b",)
    t = c.for_metric("eps_t").set_index("world")
    assert list(t.index) == ["better", "same", "worse"]
    for world in t.index:
        ref = stats.ttest_ind(samples_b[world], samples_a[world], equal_var=False)
        assert t.loc[world, "p"] == pytest.approx(ref.pvalue)
        assert t.loc[world, "t"] == pytest.approx(ref.statistic)
        assert t.loc[world, "difference"] == pytest.approx(np.mean(samples_b[world]) - np.mean(samples_a[world]))
    assert t["p_adjusted"].to_numpy() == pytest.approx(adjust_pvalues(t["p"].to_numpy(), "holm"))
    assert t.loc["better", "verdict"] == B_BETTER
    assert t.loc["worse", "verdict"] == A_BETTER
    assert t.loc["same", "verdict"] == NO_DIFFERENCE
    overall = c.overall["eps_t"]
    assert (overall.worlds, overall.a_better, overall.b_better, overall.no_difference) == (3, 1, 1, 1)
    assert (overall.b_lower, overall.b_higher) == (1, 2)
    assert overall.sign_test_p == pytest.approx(1.0)
    assert overall.verdict == "no consistent difference" and "karto" in overall.statement
    # eps_r is eps_t / 10 here: the same tests, the same verdicts.
    assert list(c.for_metric("eps_r")["verdict"]) == list(t["verdict"])
    bh = compare_campaigns(a, b, correction="bh").for_metric("eps_t")
    assert bh["p_adjusted"].to_numpy() == pytest.approx(adjust_pvalues(bh["p"].to_numpy(), "bh"))


def test_correction_can_change_a_verdict() -> None:
    # Three worlds each with p just under 0.05: significant uncorrected, not after Holm (3 * p > 0.05).
    base = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0])
    a = _frame({w: list(base) for w in "xyz"})
    shift = 3.0  # p = 0.028 for these two samples
    b = _frame({w: list(base + shift) for w in "xyz"})
    p = stats.ttest_ind(base + shift, base, equal_var=False).pvalue
    assert 0.0167 < p < 0.05
    assert set(compare_campaigns(a, b, correction="none").for_metric("eps_t")["verdict"]) == {A_BETTER}
    assert set(compare_campaigns(a, b, correction="holm").for_metric("eps_t")["verdict"]) == {NO_DIFFERENCE}


def test_overall_sign_test_decides_with_enough_worlds() -> None:
    rng = np.random.default_rng(2)
    worlds = [f"w{k}" for k in range(6)]
    a = _frame({w: list(rng.normal(0.3, 0.05, 8)) for w in worlds})
    b = _frame({w: list(rng.normal(0.1, 0.05, 8)) for w in worlds})
    overall = compare_campaigns(a, b).overall["eps_t"]
    assert overall.b_lower == 6 and overall.sign_test_p == pytest.approx(2 / 64)
    assert overall.verdict == B_BETTER


def test_trap_between_campaigns_by_hand() -> None:
    a = _frame({"w": [1.0, 2.0, 3.0]}, first_run=10)
    b = _frame({"w": [2.5, 3.5, 4.5]}, first_run=20)
    row = compare_campaigns(a, b, metrics=("eps_t",)).for_metric("eps_t").iloc[0]
    assert row["difference"] == pytest.approx(1.5)  # A better on the means
    # Only B's 2.5 beats A's 3.0: 1 of 9 single-run comparisons says B is better.
    assert row["trap_fraction"] == pytest.approx(1 / 9)
    assert (row["trap_run_a"], row["trap_run_b"]) == (12, 20)
    assert (row["trap_value_a"], row["trap_value_b"]) == (3.0, 2.5)
    assert row["trap_difference"] == pytest.approx(-0.5)


def test_too_few_runs_verdict() -> None:
    a = _frame({"w": [1.0], "v": [1.0, 2.0]})
    b = _frame({"w": [2.0, 3.0], "v": [5.0, 6.0]})
    t = compare_campaigns(a, b, metrics=("eps_t",)).for_metric("eps_t").set_index("world")
    assert t.loc["w", "verdict"] == TOO_FEW and math.isnan(t.loc["w", "p_adjusted"])
    # The family has one member, so v's p is not adjusted.
    assert t.loc["v", "p_adjusted"] == pytest.approx(t.loc["v", "p"])


def test_world_pair_traps_reproduce_the_papers_fig6() -> None:
    # E_a: mean 0.31 with one run at 0.43; E_b: mean 0.52 with one run at 0.39 (the paper's numbers).
    runs = _frame({"E_b": [0.39, 0.60, 0.57], "E_a": [0.27, 0.23, 0.43, 0.31], "E_c": [0.9, 0.95]})
    traps = world_pair_traps(runs, "eps_t")
    assert len(traps) == 3
    ab = traps[(traps["world_low"] == "E_a") & (traps["world_high"] == "E_b")].iloc[0]
    assert ab["mean_low"] == pytest.approx(0.31) and ab["mean_high"] == pytest.approx(0.52)
    assert (ab["run_low"], ab["run_high"]) == (2, 0)
    assert ab["reversed_by"] == pytest.approx(0.04)
    assert ab["reversed_fraction"] == pytest.approx(1 / 12)
    assert traps.iloc[0]["world_low"] == "E_a" and traps.iloc[0]["world_high"] == "E_b"  # largest reversal first
    assert list(traps["reversed_by"]) == sorted(traps["reversed_by"], reverse=True)


def test_bad_input_is_named() -> None:
    a = _frame({"w": [1.0, 2.0]})
    with pytest.raises(ValueError, match="campaign B is missing the column 'eps_t'"):
        compare_campaigns(a, a.drop(columns="eps_t"))
    with pytest.raises(ValueError, match="no world in common"):
        compare_campaigns(a, _frame({"other": [1.0, 2.0]}))
    with pytest.raises(ValueError, match="alpha"):
        compare_campaigns(a, a, alpha=1.5)


def test_worlds_come_in_campaign_a_s_order():
    """Not alphabetically: the order the campaign lists its worlds in (B's extra worlds left out)."""
    a = _frame({"zeta_hall": [0.1, 0.2, 0.3], "alpha_lab": [0.2, 0.3, 0.4], "mid_office": [0.3, 0.2, 0.1]})
    b = _frame({"alpha_lab": [0.2, 0.4, 0.5], "mid_office": [0.1, 0.2, 0.3], "zeta_hall": [0.1, 0.3, 0.3]})
    comparison = compare_campaigns(a, b)
    assert list(comparison.for_metric("eps_t")["world"]) == ["zeta_hall", "alpha_lab", "mid_office"]


def test_a_paired_comparisons_trap_is_the_same_run_on_both_sides() -> None:
    # a replay: run k of B is run k of A's recording; single-run comparisons are the pairs (a_k, b_k), so
    # the most misleading one is the run where B is worst against A, never two different runs
    a_values = [0.30, 0.32, 0.31, 0.29, 0.40, 0.33]
    b_values = [0.20, 0.22, 0.21, 0.19, 0.45, 0.23]  # B better on every run but run 4
    a, b = _frame({"w": a_values}), _frame({"w": b_values})
    row = compare_campaigns(a, b, paired_by="run").for_metric("eps_t").iloc[0]
    assert row["test"] == "paired t"
    assert row["trap_run_a"] == row["trap_run_b"] == 4
    assert row["trap_value_a"] == 0.40 and row["trap_value_b"] == 0.45
    assert row["trap_fraction"] == pytest.approx(1 / 6)
    # unpaired, the trap may take any run of each side: here B's run 4 against A's best run 3
    unpaired = compare_campaigns(a, b).for_metric("eps_t").iloc[0]
    assert (unpaired["trap_run_a"], unpaired["trap_run_b"]) == (3, 4)
    r = paired_reversal([0.2, 0.3, 0.5], [0.4, 0.35, 0.45])
    assert (r.i_low, r.i_high, r.fraction) == (2, 2, pytest.approx(1 / 3))
    assert r.reversed_by == pytest.approx(0.05)
