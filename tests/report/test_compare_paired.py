"""Paired comparisons of a campaign and its replay, intervals corrected like the p-values, Stouffer's overall test.

Against scipy and hand computations, and by simulation: the size of the paired and the combined tests
under no difference, the coverage of the per-world and the simultaneous intervals, and the power of the
combined test with 3 worlds, where the sign test over worlds cannot reach significance.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from slamtrials.report.combine import interval_level, one_sided_scores, stouffer
from slamtrials.report.compare import (
    A_BETTER,
    B_BETTER,
    NO_DIFFERENCE,
    TOO_FEW,
    adjust_pvalues,
    compare_campaigns,
    comparison_notes,
    welch,
)
from slamtrials.report.paired import paired_test, signed_rank_p


def _runs(values: dict[str, np.ndarray], runs: dict[str, list[int]] | None = None) -> pd.DataFrame:
    rows = []
    for world, v in values.items():
        index = runs[world] if runs else list(range(len(v)))
        for k, x in zip(index, v):
            rows.append({"world": world, "run": k, "eps_t": float(x), "eps_r": float(x) / 10.0})
    return pd.DataFrame(rows)


def _replayed(rng: np.random.Generator, worlds: int, runs: int, shift: float, noise: float, spread: float = 0.05):
    """A campaign and a "replay": per run a shared hard-or-easy level (spread) plus a small own noise."""
    level = {f"w{k}": rng.normal(0.3, spread, runs) for k in range(worlds)}
    a = {w: x + rng.normal(0.0, noise, runs) for w, x in level.items()}
    b = {w: x + shift + rng.normal(0.0, noise, runs) for w, x in level.items()}
    return a, b


# ----------------------------------------------------------------------------------- per-world paired test


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_paired_test_matches_scipy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a = rng.normal(0.3, 0.05, int(rng.integers(5, 25)))
    b = a + rng.normal(-0.01, 0.01, len(a))
    ref = stats.ttest_rel(b, a)
    r = paired_test(a, b, confidence=0.99)
    assert r.n == len(a) and r.dof == len(a) - 1
    assert r.difference == pytest.approx(np.mean(b - a)) and r.mean_b - r.mean_a == pytest.approx(r.difference)
    assert r.t == pytest.approx(ref.statistic) and r.p == pytest.approx(ref.pvalue)
    ci = ref.confidence_interval(confidence_level=0.99)
    assert (r.ci_low, r.ci_high) == pytest.approx((ci.low, ci.high))
    assert r.se == pytest.approx(np.std(b - a, ddof=1) / math.sqrt(len(a)))
    assert r.wilcoxon_p == pytest.approx(stats.wilcoxon(b - a).pvalue)
    assert r.correlation == pytest.approx(stats.pearsonr(a, b).statistic)


def test_paired_test_by_hand_and_degenerate_cases() -> None:
    a, b = [1.0, 2.0, 3.0, 4.0], [1.5, 2.4, 3.7, 4.4]  # differences 0.5 0.4 0.7 0.4
    d = np.array([0.5, 0.4, 0.7, 0.4])
    r = paired_test(a, b)
    se = d.std(ddof=1) / 2.0
    assert r.difference == pytest.approx(0.5) and r.se == pytest.approx(se) and r.t == pytest.approx(0.5 / se)
    # every difference positive, 4 pairs: the exact signed-rank p is 2 / 2^4
    assert r.wilcoxon_p == pytest.approx(2 / 16)
    same = paired_test([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])  # a replay of the same algorithm: identical errors
    assert (same.t, same.p, same.wilcoxon_p) == (0.0, 1.0, 1.0)
    shifted = paired_test([1.0, 2.0, 3.0], [1.5, 2.5, 3.5])  # a constant difference
    assert shifted.p == 0.0 and shifted.t == math.inf
    assert shifted.correlation == pytest.approx(1.0)
    assert math.isnan(paired_test([1.0, 1.0, 1.0], [1.0, 2.0, 3.0]).correlation)  # a constant side
    one = paired_test([1.0], [2.0])
    assert one.difference == 1.0 and math.isnan(one.p) and math.isnan(one.wilcoxon_p)
    assert signed_rank_p([0.0, 0.0]) == 1.0
    with pytest.raises(ValueError, match="same length"):
        paired_test([1.0, 2.0], [1.0])


def test_pairing_removes_the_shared_variation_that_welch_keeps() -> None:
    a, b = _replayed(np.random.default_rng(4), 1, 10, shift=-0.005, noise=0.003)
    paired = paired_test(a["w0"], b["w0"])
    unpaired = welch(a["w0"], b["w0"])
    assert paired.difference == pytest.approx(unpaired.difference)
    assert paired.se < unpaired.se / 5 and paired.p < 0.01 < 0.5 < unpaired.p


# ---------------------------------------------------------------------------------- sizes and coverage


@pytest.mark.slow
def test_paired_test_rejects_alpha_of_the_time_under_no_difference() -> None:
    rng = np.random.default_rng(2026)
    reps, n, alpha = 4000, 10, 0.05
    level = rng.normal(0.3, 0.05, (reps, n))
    a = level + rng.normal(0.0, 0.004, (reps, n))
    b = level + rng.normal(0.0, 0.004, (reps, n))
    p = np.array([paired_test(a[k], b[k]).p for k in range(reps)])
    # binomial standard error of the rate: sqrt(0.05 * 0.95 / 4000) = 0.0034
    assert abs(np.mean(p <= alpha) - alpha) < 0.012
    assert abs(np.mean(p <= 0.01) - 0.01) < 0.006


@pytest.mark.slow
def test_stouffer_over_three_worlds_has_its_size_paired_and_welch() -> None:
    rng = np.random.default_rng(7)
    reps, alpha = 2000, 0.05
    rejected = {"paired": 0, "welch": 0}
    for _ in range(reps):
        a, b = _replayed(rng, 3, 10, shift=0.0, noise=0.004)
        paired = [paired_test(a[w], b[w]) for w in a]
        unpaired = [welch(a[w], b[w]) for w in a]
        rejected["paired"] += stouffer([r.t for r in paired], [r.dof for r in paired]).p <= alpha
        rejected["welch"] += stouffer([r.t for r in unpaired], [r.dof for r in unpaired]).p <= alpha
    assert abs(rejected["paired"] / reps - alpha) < 0.015  # 3 standard errors
    # Welch on correlated pairs is valid but conservative (its variance ignores the shared part)
    assert rejected["welch"] / reps < alpha + 0.014


@pytest.mark.slow
def test_intervals_cover_each_world_and_all_worlds_together() -> None:
    rng = np.random.default_rng(11)
    reps, alpha, truth = 2000, 0.05, np.array([-0.004, 0.0, 0.003])
    alone = together = 0
    for _ in range(reps):
        level = rng.normal(0.3, 0.05, (3, 10))
        a = level + rng.normal(0.0, 0.004, (3, 10))
        b = level + truth[:, None] + rng.normal(0.0, 0.004, (3, 10))
        one = [paired_test(a[k], b[k], confidence=1 - alpha) for k in range(3)]
        adjusted = [paired_test(a[k], b[k], confidence=1 - alpha / 3) for k in range(3)]  # as compare's Holm
        alone += sum(r.ci_low <= x <= r.ci_high for r, x in zip(one, truth))
        together += all(r.ci_low <= x <= r.ci_high for r, x in zip(adjusted, truth))
    assert abs(alone / (3 * reps) - (1 - alpha)) < 0.01  # each 95 % interval covers 95 % of the time
    # Bonferroni's intervals (each at 1 - alpha/3) all cover together at least 1 - alpha of the time; for
    # independent worlds exactly (1 - alpha/3)^3 = 95.08 % (binomial standard error 0.5 %)
    assert abs(together / reps - (1 - alpha / 3) ** 3) < 0.015


# -------------------------------------------------------------------------------- the overall verdict


def test_stouffer_by_hand() -> None:
    t, dof = np.array([-2.0, -1.0, 0.5]), np.array([9.0, 9.0, 9.0])
    z = [math.copysign(stats.norm.isf(stats.t.sf(abs(x), 9.0)), x) for x in t]
    assert one_sided_scores(t, dof) == pytest.approx(z)
    r = stouffer(t, dof)
    assert r.z == pytest.approx(sum(z) / math.sqrt(3)) and r.worlds == 3
    assert r.p == pytest.approx(2 * stats.norm.cdf(-abs(sum(z) / math.sqrt(3))))
    # opposite worlds cancel: B much better in one world, much worse in the other is no consistent difference
    assert stouffer([-4.0, 4.0], [9.0, 9.0]).p == pytest.approx(1.0)
    # large t keep their precision (computed from the tail)
    assert one_sided_scores([-40.0], [9.0])[0] == pytest.approx(-stats.norm.isf(stats.t.sf(40.0, 9.0)))
    assert math.isnan(stouffer([math.nan], [9.0]).z) and stouffer([math.nan, 1.0], [9.0, 9.0]).worlds == 1
    assert math.isnan(stouffer([math.inf, -math.inf], [9.0, 9.0]).p)


def test_three_worlds_small_paired_difference_is_significant_overall_where_the_sign_test_cannot_be() -> None:
    rng = np.random.default_rng(3)
    a, b = _replayed(rng, 3, 10, shift=-0.003, noise=0.004)
    c = compare_campaigns(_runs(a), _runs(b), labels=("gmapping", "p80"), paired_by="p80 is a replay of gmapping")
    overall = c.overall["eps_t"]
    assert c.pairing == "paired (p80 is a replay of gmapping)" and c.paired
    assert overall.b_lower == 3 and overall.sign_test_p == pytest.approx(0.25)  # the sign test's floor
    assert overall.p < 0.01 and overall.z < 0 and overall.verdict == B_BETTER
    assert overall.test == "Stouffer's Z over the worlds' one-sided paired t-tests"
    assert "gmapping" in overall.statement and "p80 is better overall" in overall.statement
    assert "sign test over worlds p = 0.25" in overall.statement
    t = c.for_metric("eps_t")
    assert set(t["test"]) == {"paired t"}
    for _, row in t.iterrows():
        ref = stats.ttest_rel(b[row["world"]], a[row["world"]])
        assert row["p"] == pytest.approx(ref.pvalue) and row["t"] == pytest.approx(ref.statistic)
        assert row["wilcoxon_p"] == pytest.approx(stats.wilcoxon(b[row["world"]] - a[row["world"]]).pvalue)
    expected = stouffer(t["t"].to_numpy(), t["dof"].to_numpy())
    assert (overall.z, overall.p) == pytest.approx((expected.z, expected.p))
    assert t["wilcoxon_p_adjusted"].to_numpy() == pytest.approx(adjust_pvalues(t["wilcoxon_p"].to_numpy()))
    # the same numbers unpaired: Welch sees nothing in any world, nor overall
    welch_c = compare_campaigns(_runs(a), _runs(b))
    assert welch_c.pairing == "unpaired (Welch)" and not welch_c.paired
    assert set(welch_c.for_metric("eps_t")["verdict"]) == {NO_DIFFERENCE}
    assert welch_c.overall["eps_t"].verdict == "no consistent difference"
    assert welch_c.overall["eps_t"].test == "Stouffer's Z over the worlds' one-sided Welch t-tests"
    assert np.isnan(welch_c.table["wilcoxon_p"]).all() and (welch_c.table["test"] == "Welch").all()


@pytest.mark.slow  # by simulation
def test_power_of_the_combined_test_with_three_worlds() -> None:
    rng = np.random.default_rng(5)
    reps, alpha = 300, 0.05
    stouffer_hits = sign_hits = 0
    for _ in range(reps):
        a, b = _replayed(rng, 3, 10, shift=-0.003, noise=0.004)
        tests = [paired_test(a[w], b[w]) for w in a]
        stouffer_hits += stouffer([r.t for r in tests], [r.dof for r in tests]).p <= alpha
        lower = sum(r.difference < 0 for r in tests)
        sign_hits += stats.binomtest(lower, 3, 0.5).pvalue <= alpha
    assert sign_hits == 0  # 3 worlds: the sign test cannot go below 0.25
    # per world t is about 0.003 / (0.004 sqrt(2) / sqrt(10)) = 1.68, so Z is about 1.68 sqrt(3) = 2.9 and the
    # power about P(N(2.9, 1) > 1.96) = 0.83 (the t tails make it a little less)
    assert 0.7 < stouffer_hits / reps < 0.95


def test_a_consistent_welch_difference_over_three_worlds_is_found_overall() -> None:
    rng = np.random.default_rng(8)
    a = {f"w{k}": rng.normal(0.30 + 0.1 * k, 0.05, 10) for k in range(3)}
    b = {w: rng.normal(x.mean() - 0.035, 0.05, 10) for w, x in a.items()}
    overall = compare_campaigns(_runs(a), _runs(b)).overall["eps_t"]
    assert overall.sign_test_p >= 0.25 and overall.p <= 0.05 and overall.verdict == B_BETTER


# -------------------------------------------------------------------- intervals corrected like the p-values


def test_interval_levels() -> None:
    assert interval_level(0.05, "none", [0.01, 0.2, 0.5]).confidence == pytest.approx(0.95)
    holm = interval_level(0.05, "holm", [0.03, 0.2, math.nan, 0.5])
    assert holm.confidence == pytest.approx(1 - 0.05 / 3) and "Bonferroni, 3 worlds" in holm.label
    bh = interval_level(0.05, "bh", [0.01, 0.04, 0.5, 0.9])  # adjusted p: 2 selected of 4
    assert bh.confidence == pytest.approx(1 - 2 * 0.05 / 4) and "2 of 4 selected" in bh.label
    assert interval_level(0.05, "bh", [0.3, 0.9]).confidence == pytest.approx(1 - 0.05 / 2)
    assert interval_level(0.05, "holm", [0.3]).confidence == pytest.approx(0.95)
    with pytest.raises(ValueError, match="correction"):
        interval_level(0.05, "bonferroni", [0.1, 0.2])


@pytest.mark.parametrize("correction", ["holm", "bh", "none"])
@pytest.mark.parametrize("paired", [True, False])
def test_an_interval_that_excludes_zero_goes_with_a_significant_verdict(correction: str, paired: bool) -> None:
    rng = np.random.default_rng(21)
    for _ in range(30):
        worlds = int(rng.integers(2, 7))
        a, b = {}, {}
        for k in range(worlds):
            level = rng.normal(0.3, 0.05, 8)
            a[f"w{k}"] = level + rng.normal(0.0, 0.01, 8)
            b[f"w{k}"] = level + rng.normal(rng.choice([-0.012, 0.0, 0.008]), 0.01, 8)
        c = compare_campaigns(
            _runs(a), _runs(b), metrics=("eps_t",), correction=correction, paired_by="test" if paired else None
        )
        t = c.for_metric("eps_t")
        excludes = (t["ci_adj_low"] > 0) | (t["ci_adj_high"] < 0)
        significant = t["verdict"].isin([A_BETTER, B_BETTER])
        assert not (excludes & ~significant).any()  # never an interval off 0 beside "no significant difference"
        if correction != "holm":  # BH's and the unadjusted intervals match the verdicts exactly
            assert (excludes == significant).all()
        assert (t["ci_adj_level"] == c.intervals["eps_t"].confidence).all()
        first = t.iloc[0]
        world = first["world"]
        test = paired_test if paired else welch
        again = test(a[world], b[world], confidence=first["ci_adj_level"])
        assert (first["ci_adj_low"], first["ci_adj_high"]) == pytest.approx((again.ci_low, again.ci_high))
        assert ((t["ci_adj_high"] - t["ci_adj_low"]) >= (t["ci_high"] - t["ci_low"]) - 1e-15).all()


def test_the_issue_example_is_labelled_both_ways() -> None:
    # One world significant alone (its 95 % interval excludes 0) but not after Holm over three worlds: the
    # interval shown beside the verdict is the simultaneous one, which reaches 0.
    base = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0])
    a = _runs({w: base for w in "xyz"})
    b = _runs({w: base + 3.0 for w in "xyz"})
    row = compare_campaigns(a, b).for_metric("eps_t").iloc[0]
    assert row["ci_low"] > 0 and row["verdict"] == NO_DIFFERENCE
    assert row["ci_adj_low"] < 0 < row["ci_adj_high"] and row["ci_adj_level"] == pytest.approx(1 - 0.05 / 3)


# ------------------------------------------------------------------------------------- pairing by run


def test_statement_without_any_test() -> None:
    c = compare_campaigns(_runs({"w": np.array([1.0])}), _runs({"w": np.array([2.0])}), paired_by="test")
    overall = c.overall["eps_t"]
    assert math.isnan(overall.p) and overall.worlds_tested == 0 and overall.verdict == "no consistent difference"
    assert "paired t-tests: no world has a test;" in overall.statement and overall.too_few == 1


def test_runs_are_paired_by_index_and_the_rest_left_out() -> None:
    a = _runs({"w": np.array([1.0, 2.0, 3.0, 4.0, 5.0]), "v": np.array([1.0])}, {"w": [0, 1, 2, 3, 4], "v": [0]})
    b = _runs({"w": np.array([5.1, 3.2, 2.1, 9.0]), "v": np.array([2.0])}, {"w": [4, 2, 1, 7], "v": [3]})
    c = compare_campaigns(a, b, metrics=("eps_t",), paired_by="test")
    t = c.for_metric("eps_t").set_index("world")
    assert (t.loc["w", "n_a"], t.loc["w", "left_out_a"], t.loc["w", "left_out_b"]) == (3, 2, 1)
    assert t.loc["w", "difference"] == pytest.approx(np.mean([5.1 - 5.0, 3.2 - 3.0, 2.1 - 2.0]))
    assert t.loc["w", "p"] == pytest.approx(stats.ttest_rel([5.1, 3.2, 2.1], [5.0, 3.0, 2.0]).pvalue)
    assert t.loc["v", "verdict"] == TOO_FEW and t.loc["v", "n_a"] == 0  # no run in common
    notes = comparison_notes(c)
    assert any("left out of the paired tests: w 2 of A, 1 of B; v 1 of A, 1 of B" in n for n in notes)
    twice = _runs({"w": np.array([1.0, 2.0])}, {"w": [3, 3]})
    with pytest.raises(ValueError, match="run 3 twice"):
        compare_campaigns(twice, b, paired_by="test")


def test_notes_when_the_wilcoxon_check_cannot_agree() -> None:
    # 5 pairs, every difference negative and tight: the paired t-test is significant, the exact
    # signed-rank test cannot go below 2/2^5 = 0.0625.
    a = _runs({"w": np.array([0.30, 0.35, 0.28, 0.40, 0.33])})
    b = _runs({"w": np.array([0.29, 0.339, 0.271, 0.389, 0.321])})
    c = compare_campaigns(a, b, metrics=("eps_t",), paired_by="test")
    row = c.for_metric("eps_t").iloc[0]
    assert row["verdict"] == B_BETTER and row["wilcoxon_p"] == pytest.approx(0.0625)
    (note,) = comparison_notes(c)
    assert "the Wilcoxon signed-rank check does not" in note and "cannot go below 0.0625" in note
