"""Statistical comparison of two campaigns (A and B, e.g. two SLAM algorithms on the same worlds).

Per world and metric (``eps_t`` in m, ``eps_r`` in rad; lower is better), the difference of the mean
errors ``B - A`` and its test, by one of two tests:

- **paired** when the two campaigns share their recorded data (B a replay of A, A of B, or both replays
  of one source: run ``i`` of world ``w`` comes from the same recorded laser and odometry in both).
  Runs are paired by ``(world, run)`` present in both (the others are left out and counted); the test is
  the paired t-test on the run-by-run differences (:func:`slamtrials.report.paired.paired_test`, equal
  to ``scipy.stats.ttest_rel``), with the Wilcoxon signed-rank test of the same differences as a check
  (its p-value corrected the same way, shown beside);
- **unpaired (Welch)** otherwise: Welch's unequal-variance t-test (standard error
  ``sqrt(s_A^2/n_A + s_B^2/n_B)``, Welch-Satterthwaite degrees of freedom; equal to
  ``scipy.stats.ttest_ind(b, a, equal_var=False)``).

The p-values are adjusted for multiple comparisons across the worlds of one metric (each metric is its
own family): Holm-Bonferroni by default (family-wise error rate), Benjamini-Hochberg on request (false
discovery rate), or none. The verdict at level ``alpha`` is taken on the adjusted p-value: ``"A
better"``, ``"B better"``, ``"no significant difference"``, or ``"too few runs"`` (fewer than 2 runs on a
side, or 2 pairs). Two intervals per world: ``ci_low, ci_high`` at ``1 - alpha`` for that world alone
(unadjusted), and ``ci_adj_low, ci_adj_high`` at the level that matches the correction
(:func:`slamtrials.report.combine.interval_level`: Bonferroni's simultaneous intervals for Holm,
Benjamini-Yekutieli's for BH), the one shown beside the verdicts.

Overall, per metric: **Stouffer's combination** of the worlds' one-sided tests
(:func:`slamtrials.report.combine.stouffer`): each world's t statistic (paired or Welch) becomes a signed
normal score, the scores add up over the worlds (each world once), and ``Z < 0`` at two-sided
``p <= alpha`` says B is better overall. Worlds that disagree cancel, so the verdict means a consistent
difference; three worlds with a clear effect reach it, where the former **sign test** over worlds (kept
as a labelled check: the worlds where B's mean is lower against those where it is higher) cannot go below
p = 0.25 with 3 worlds and needs 6 to reach p < 0.05.

The trap of the paper's Fig. 6, made visible: comparing single runs can give the opposite verdict from
comparing means. For two samples ``x`` (lower mean) and ``y`` (higher mean) the *reversal fraction* is
the fraction of the pairs ``(x_i, y_j)`` with ``x_i > y_j`` (ties count as not reversed), and the *most
misleading pair* is ``(argmax x, argmin y)``, whose reversed difference ``max x - min y`` is the largest.
:func:`compare_campaigns` reports it for A vs B in every world (over the paired runs when paired);
:func:`world_pair_traps` for every pair of worlds of one campaign (the paper's case: a bad run of the
easier world beats a good run of the harder one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations
from typing import Literal

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import stats

from slamtrials.report.combine import IntervalLevel, interval_level, stouffer
from slamtrials.report.paired import PairedResult, paired_test
from slamtrials.report.tables import METRICS, UNITS, check_metric

__all__ = [
    "Correction",
    "VERDICTS",
    "A_BETTER",
    "B_BETTER",
    "NO_DIFFERENCE",
    "TOO_FEW",
    "WelchResult",
    "welch",
    "adjust_pvalues",
    "Reversal",
    "reversal",
    "OverallVerdict",
    "Comparison",
    "UNITS",
    "compare_campaigns",
    "comparison_notes",
    "world_pair_traps",
    "paired_reversal",
    "sign_test",
]

Correction = Literal["holm", "bh", "none"]
A_BETTER, B_BETTER, NO_DIFFERENCE, TOO_FEW = "A better", "B better", "no significant difference", "too few runs"
#: The per-world verdicts.
VERDICTS = (A_BETTER, B_BETTER, NO_DIFFERENCE, TOO_FEW)


@dataclass(frozen=True)
class WelchResult:
    """Welch's comparison of two samples: difference of means ``mean_b - mean_a`` and its test.

    Attributes
    ----------
    n_a, n_b, mean_a, mean_b, std_a, std_b:
        Sizes, means and sample standard deviations (divisor ``n - 1``) of the two samples.
    difference:
        ``mean_b - mean_a`` (units of the values).
    se:
        Its standard error ``sqrt(s_a^2/n_a + s_b^2/n_b)``.
    dof:
        Welch-Satterthwaite degrees of freedom; ``n_a + n_b - 2`` when both samples are constant.
    t:
        ``difference / se`` (``+-inf`` when ``se == 0`` and the means differ, 0 when they are equal).
    p:
        Two-sided p-value of ``t`` under Student t with ``dof``.
    ci_low, ci_high:
        ``difference -+ q se`` with ``q`` the t quantile of ``confidence``.
    confidence:
        Level of the interval.

    Every statistic but the sizes and means is NaN when a sample has fewer than 2 values.
    """

    n_a: int
    n_b: int
    mean_a: float
    mean_b: float
    std_a: float
    std_b: float
    difference: float
    se: float
    dof: float
    t: float
    p: float
    ci_low: float
    ci_high: float
    confidence: float


def welch(a: ArrayLike, b: ArrayLike, *, confidence: float = 0.95) -> WelchResult:
    """Welch's unequal-variance t-test and interval of ``mean(b) - mean(a)`` for samples ``a [n_a]``, ``b [n_b]``."""
    a = np.asarray(a, dtype=np.float64).reshape(-1)
    b = np.asarray(b, dtype=np.float64).reshape(-1)
    if len(a) == 0 or len(b) == 0:
        raise ValueError(f"need at least one value on each side, got {len(a)} and {len(b)}")
    if not (0.0 < confidence < 1.0):
        raise ValueError(f"confidence must be strictly between 0 and 1, got {confidence}")
    na, nb = len(a), len(b)
    ma, mb = float(a.mean()), float(b.mean())
    diff = mb - ma
    nan = math.nan
    if na < 2 or nb < 2:
        return WelchResult(na, nb, ma, mb, nan, nan, diff, nan, nan, nan, nan, nan, nan, confidence)
    sa, sb = float(a.std(ddof=1)), float(b.std(ddof=1))
    va, vb = sa * sa / na, sb * sb / nb
    se = math.sqrt(va + vb)
    if se == 0.0:
        dof = float(na + nb - 2)
        t = 0.0 if diff == 0.0 else math.copysign(math.inf, diff)
        p = 1.0 if diff == 0.0 else 0.0
    else:
        dof = (va + vb) ** 2 / (va * va / (na - 1) + vb * vb / (nb - 1))
        t = diff / se
        p = float(2.0 * stats.t.sf(abs(t), dof))
    half = float(stats.t.ppf(0.5 + confidence / 2.0, dof)) * se
    return WelchResult(na, nb, ma, mb, sa, sb, diff, se, dof, t, p, diff - half, diff + half, confidence)


def adjust_pvalues(p: ArrayLike, method: Correction = "holm") -> NDArray[np.float64]:
    """P-values ``[m]`` adjusted for multiple comparisons; NaN entries stay NaN and are not counted in ``m``.

    ``"holm"``: Holm-Bonferroni step-down, ``p_(i) -> max_{j <= i} min(1, (m - j + 1) p_(j))`` over the
    ascending order. ``"bh"``: Benjamini-Hochberg step-up, ``p_(i) -> min_{j >= i} min(1, m p_(j) / j)``.
    ``"none"``: unchanged. Reject at level ``alpha`` where the adjusted value is ``<= alpha``.
    """
    p = np.asarray(p, dtype=np.float64).reshape(-1)
    out = p.copy()
    valid = np.flatnonzero(np.isfinite(p))
    if method == "none" or len(valid) == 0:
        if method not in ("holm", "bh", "none"):
            raise ValueError(f"unknown correction {method!r}; use 'holm', 'bh' or 'none'")
        return out
    m = len(valid)
    order = valid[np.argsort(p[valid], kind="stable")]
    ranked = p[order]
    rank = np.arange(1, m + 1)
    if method == "holm":
        adjusted = np.maximum.accumulate(np.minimum(1.0, (m - rank + 1) * ranked))
    elif method == "bh":
        adjusted = np.minimum.accumulate(np.minimum(1.0, m * ranked / rank)[::-1])[::-1]
    else:
        raise ValueError(f"unknown correction {method!r}; use 'holm', 'bh' or 'none'")
    out[order] = adjusted
    return out


def sign_test(positive: int, negative: int) -> float:
    """Exact two-sided sign test p-value of ``positive`` vs ``negative`` signs (1 when both are 0)."""
    n = positive + negative
    return 1.0 if n == 0 else float(stats.binomtest(positive, n, 0.5).pvalue)


@dataclass(frozen=True)
class Reversal:
    """Single-run comparisons that contradict the comparison of means (the paper's Fig. 6 trap).

    Attributes
    ----------
    fraction:
        Fraction of the pairs ``(x_i, y_j)`` with ``x_i > y_j``, ``x`` the sample of lower mean; NaN when
        the means are equal.
    i_low, i_high:
        Positions of the most misleading pair (``argmax x``, ``argmin y``) in the given arrays.
    reversed_by:
        ``max x - min y``: how much the most misleading single run of the better side is worse than the
        single run of the worse side (positive when some pair is reversed).
    """

    fraction: float
    i_low: int
    i_high: int
    reversed_by: float


def reversal(low: ArrayLike, high: ArrayLike) -> Reversal:
    """The Fig. 6 trap between samples ``low [n]`` (lower mean) and ``high [m]`` (higher mean).

    Counts pairs in ``O((n + m) log m)`` by sorting, not by forming the ``n x m`` pairs.
    """
    x = np.asarray(low, dtype=np.float64).reshape(-1)
    y = np.asarray(high, dtype=np.float64).reshape(-1)
    if len(x) == 0 or len(y) == 0:
        raise ValueError("need at least one value on each side")
    i, j = int(np.argmax(x)), int(np.argmin(y))
    if x.mean() == y.mean():
        return Reversal(math.nan, i, j, float(x[i] - y[j]))
    below = np.searchsorted(np.sort(y, kind="stable"), x, side="left")  # for each x_i: how many y_j < x_i
    return Reversal(float(below.sum()) / (len(x) * len(y)), i, j, float(x[i] - y[j]))


def paired_reversal(low: ArrayLike, high: ArrayLike) -> Reversal:
    """The Fig. 6 trap of a paired comparison: ``low [n]`` and ``high [n]`` are the same runs (run ``k``
    of each side replayed from the same recording), ``low`` of lower mean. A single-run comparison is one
    such pair, so ``fraction`` is the share of runs ``k`` with ``low_k > high_k`` and the most misleading
    pair is the run where ``low_k - high_k`` is largest (``i_low == i_high``)."""
    x = np.asarray(low, dtype=np.float64).reshape(-1)
    y = np.asarray(high, dtype=np.float64).reshape(-1)
    if len(x) == 0 or len(x) != len(y):
        raise ValueError(f"need the same runs on both sides, got {len(x)} and {len(y)}")
    k = int(np.argmax(x - y))
    if x.mean() == y.mean():
        return Reversal(math.nan, k, k, float(x[k] - y[k]))
    return Reversal(float(np.count_nonzero(x > y)) / len(x), k, k, float(x[k] - y[k]))


@dataclass(frozen=True)
class OverallVerdict:
    """The verdict over all compared worlds for one metric.

    Attributes
    ----------
    metric:
        ``"eps_t"`` or ``"eps_r"``.
    worlds:
        Worlds compared.
    a_better, b_better, no_difference, too_few:
        Worlds with each per-world verdict (after correction).
    b_lower, b_higher, ties:
        Worlds where B's mean is lower than, higher than, equal to A's.
    test:
        The overall test, in words (``"Stouffer's Z over the worlds' one-sided paired t-tests"``).
    z, p:
        Stouffer's combined score (negative: B better) and its two-sided p-value; NaN when no world has a
        test.
    worlds_tested:
        Worlds that entered Stouffer's test (those with a per-world test).
    mean_difference, median_difference:
        Mean and median over worlds of ``mean_B - mean_A`` (units of the metric).
    sign_test_p:
        The check: exact two-sided sign test over worlds of ``b_lower`` vs ``b_higher``.
    verdict:
        ``"A better"``, ``"B better"`` (Stouffer's test significant at ``alpha``) or
        ``"no consistent difference"``.
    statement:
        One sentence that says the above.
    """

    metric: str
    worlds: int
    a_better: int
    b_better: int
    no_difference: int
    too_few: int
    b_lower: int
    b_higher: int
    ties: int
    test: str
    z: float
    p: float
    worlds_tested: int
    mean_difference: float
    median_difference: float
    sign_test_p: float
    verdict: str
    statement: str


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare_campaigns`.

    Attributes
    ----------
    table:
        One row per (world, metric), sorted by metric then world. Columns: ``world``, ``metric``,
        ``test`` (``"paired t"`` or ``"Welch"``), ``n_a``, ``n_b`` (runs compared: the pairs when paired),
        ``left_out_a``, ``left_out_b`` (runs of the world without a partner in the other campaign, left
        out of a paired test; 0 for Welch), ``mean_a``, ``mean_b``, ``std_a``, ``std_b``,
        ``std_difference`` (of the run-by-run differences), ``correlation`` (of the paired errors; NaN
        for Welch), ``difference``
        (``mean_b - mean_a``), ``se``, ``dof``, ``t``, ``p``, ``p_adjusted``, ``wilcoxon_p``,
        ``wilcoxon_p_adjusted`` (the signed-rank check, corrected like ``p``; NaN for Welch),
        ``ci_low``, ``ci_high`` (``1 - alpha``, this world alone), ``ci_adj_low``, ``ci_adj_high``,
        ``ci_adj_level`` (the interval adjusted like the p-values, and its level), ``verdict``; and the
        Fig. 6 trap: ``trap_fraction`` (fraction of (run of A, run of B) pairs whose comparison
        contradicts the sign of the difference of means), ``trap_run_a``, ``trap_run_b`` (``run``
        indexes of the most misleading pair), ``trap_value_a``, ``trap_value_b`` (their errors),
        ``trap_difference`` (``value_b - value_a``, of the opposite sign to ``difference`` when the pair
        is reversed).
    overall:
        ``{metric: OverallVerdict}``.
    intervals:
        ``{metric: IntervalLevel}``: level and label of ``ci_adj_*``.
    alpha, correction, labels:
        The settings; ``labels`` name A and B in statements and plots.
    pairing:
        ``"paired (<what the campaigns share>)"`` or ``"unpaired (Welch)"``.
    only_a, only_b:
        Worlds present in one campaign only (not compared).
    """

    table: pd.DataFrame
    overall: dict[str, OverallVerdict]
    intervals: dict[str, IntervalLevel]
    alpha: float
    correction: str
    labels: tuple[str, str]
    pairing: str
    only_a: tuple[str, ...]
    only_b: tuple[str, ...]

    @property
    def paired(self) -> bool:
        """Whether the per-world tests are paired."""
        return self.pairing.startswith("paired")

    def for_metric(self, metric: str) -> pd.DataFrame:
        """The rows of ``table`` of one metric, indexed from 0."""
        return self.table[self.table["metric"] == metric].reset_index(drop=True)


def _pairs(
    world: str, a: NDArray, runs_a: NDArray, b: NDArray, runs_b: NDArray
) -> tuple[NDArray, NDArray, NDArray, int, int]:
    """The runs of one world present in both campaigns, by run index: ``(a [n], b [n], runs [n], left_a, left_b)``."""
    for runs, name in ((runs_a, "A"), (runs_b, "B")):
        unique, counts = np.unique(runs, return_counts=True)
        if (counts > 1).any():
            raise ValueError(f"campaign {name}: world {world!r} has run {int(unique[counts > 1][0])} twice")
    common, ia, ib = np.intersect1d(runs_a, runs_b, assume_unique=True, return_indices=True)
    return a[ia], b[ib], common, len(runs_a) - len(common), len(runs_b) - len(common)


def _world_row(
    world: str,
    metric: str,
    a: NDArray,
    runs_a: NDArray,
    b: NDArray,
    runs_b: NDArray,
    confidence: float,
    paired: bool,
) -> dict:
    left_a = left_b = 0
    if paired:
        a, b, runs, left_a, left_b = _pairs(world, a, runs_a, b, runs_b)
        runs_a = runs_b = runs
    row: dict = {"world": world, "metric": metric, "test": "paired t" if paired else "Welch"}
    if paired and len(a) == 0:
        nan = math.nan
        row.update({"n_a": 0, "n_b": 0, "left_out_a": left_a, "left_out_b": left_b})
        row.update(dict.fromkeys(("mean_a", "mean_b", "std_a", "std_b", "std_difference", "correlation"), nan))
        row["difference"] = nan
        row.update(dict.fromkeys(("se", "dof", "t", "p", "wilcoxon_p", "ci_low", "ci_high"), nan))
        row.update({"trap_fraction": nan, "trap_run_a": -1, "trap_run_b": -1})
        row.update(dict.fromkeys(("trap_value_a", "trap_value_b", "trap_difference"), nan))
        return row
    r: PairedResult | WelchResult
    if paired:
        r = paired_test(a, b, confidence=confidence)
        n_a = n_b = r.n
        std_difference, correlation, wilcoxon_p = r.std_difference, r.correlation, r.wilcoxon_p
    else:
        r = welch(a, b, confidence=confidence)
        n_a, n_b = r.n_a, r.n_b
        std_difference = correlation = wilcoxon_p = math.nan
    row.update(
        {
            "n_a": n_a,
            "n_b": n_b,
            "left_out_a": left_a,
            "left_out_b": left_b,
            "mean_a": r.mean_a,
            "mean_b": r.mean_b,
            "std_a": r.std_a,
            "std_b": r.std_b,
            "std_difference": std_difference,
            "correlation": correlation,
            "difference": r.difference,
            "se": r.se,
            "dof": r.dof,
            "t": r.t,
            "p": r.p,
            "wilcoxon_p": wilcoxon_p,
            "ci_low": r.ci_low,
            "ci_high": r.ci_high,
        }
    )
    # paired: a single-run comparison is run k of A against run k of B; unpaired: any run against any
    trap = paired_reversal if paired else reversal
    if r.difference > 0:  # A has the lower mean: a B run below an A run contradicts it
        rev = trap(a, b)
        ia, ib = rev.i_low, rev.i_high
    else:
        rev = trap(b, a)
        ib, ia = rev.i_low, rev.i_high
    row.update(
        {
            "trap_fraction": rev.fraction,
            "trap_run_a": int(runs_a[ia]),
            "trap_run_b": int(runs_b[ib]),
            "trap_value_a": float(a[ia]),
            "trap_value_b": float(b[ib]),
            "trap_difference": float(b[ib] - a[ia]),
        }
    )
    return row


def _adjusted_intervals(table: pd.DataFrame, level: IntervalLevel) -> tuple[NDArray, NDArray]:
    """``difference -+ q se`` with ``q`` the t quantile of ``level`` (NaN where the world has no test)."""
    diff, se, dof = (table[c].to_numpy(dtype=np.float64) for c in ("difference", "se", "dof"))
    half = np.full(len(table), np.nan)
    ok = np.isfinite(se) & np.isfinite(dof)
    half[ok] = stats.t.ppf(0.5 + level.confidence / 2.0, dof[ok]) * se[ok]
    return diff - half, diff + half


def _verdict(row: pd.Series, alpha: float) -> str:
    if not np.isfinite(row["p_adjusted"]):
        return TOO_FEW
    if row["p_adjusted"] > alpha or row["difference"] == 0:
        return NO_DIFFERENCE
    return B_BETTER if row["difference"] < 0 else A_BETTER


def _overall(
    metric: str, rows: pd.DataFrame, alpha: float, correction: str, labels: tuple[str, str], paired: bool
) -> OverallVerdict:
    counts = rows["verdict"].value_counts()
    tested = rows[np.isfinite(rows["t"].to_numpy(dtype=np.float64))]
    combined = stouffer(tested["t"].to_numpy(dtype=np.float64), tested["dof"].to_numpy(dtype=np.float64))
    differences = rows["difference"].to_numpy(dtype=np.float64)
    differences = differences[np.isfinite(differences)]
    lower, higher = int((differences < 0).sum()), int((differences > 0).sum())
    ties = len(differences) - lower - higher
    sign_p = sign_test(lower, higher)
    mean = float(np.mean(np.sort(differences, kind="stable"))) if len(differences) else math.nan
    median = float(np.median(differences)) if len(differences) else math.nan
    name_a, name_b = labels
    test = f"Stouffer's Z over the worlds' one-sided {'paired' if paired else 'Welch'} t-tests"
    if combined.p <= alpha and combined.z != 0:
        verdict = B_BETTER if combined.z < 0 else A_BETTER
        head = f"{name_b if combined.z < 0 else name_a} is better overall in {metric}"
    else:
        verdict = "no consistent difference"
        head = f"no consistent difference in {metric}"
    unit = UNITS.get(metric, "")
    evidence = (
        f"{test}, {combined.worlds} worlds, Z = {combined.z:.2f}, p = {combined.p:.3g}"
        if math.isfinite(combined.p)
        else f"{test}: no world has a test"
        if combined.worlds == 0
        else f"{test}: each campaign is better without error in some world"
    )
    statement = (
        f"{head}: {evidence}; "
        f"mean over worlds of {name_b} \u2212 {name_a} = {mean:.3g} {unit}; "
        f"{name_b} has the lower mean in {lower} and the higher in {higher} of {len(rows)} worlds "
        f"(check: sign test over worlds p = {sign_p:.3g}); significant per world at {alpha:g} after {correction}: "
        f"{name_a} better in {int(counts.get(A_BETTER, 0))}, {name_b} better in {int(counts.get(B_BETTER, 0))}."
    )
    return OverallVerdict(
        metric=metric,
        worlds=len(rows),
        a_better=int(counts.get(A_BETTER, 0)),
        b_better=int(counts.get(B_BETTER, 0)),
        no_difference=int(counts.get(NO_DIFFERENCE, 0)),
        too_few=int(counts.get(TOO_FEW, 0)),
        b_lower=lower,
        b_higher=higher,
        ties=ties,
        test=test,
        z=combined.z,
        p=combined.p,
        worlds_tested=combined.worlds,
        mean_difference=mean,
        median_difference=median,
        sign_test_p=sign_p,
        verdict=verdict,
        statement=statement,
    )


def compare_campaigns(
    a: pd.DataFrame,
    b: pd.DataFrame,
    *,
    metrics: tuple[str, ...] = METRICS,
    alpha: float = 0.05,
    correction: Correction = "holm",
    labels: tuple[str, str] = ("A", "B"),
    paired_by: str | None = None,
) -> Comparison:
    """Compare campaign B with campaign A world by world (see the module docstring for the method).

    Parameters
    ----------
    a, b:
        Runs of the two campaigns, one row per finished run, columns ``world``, ``run`` and the metrics.
    metrics:
        Which of ``"eps_t"`` (m), ``"eps_r"`` (rad) to compare.
    alpha:
        Significance level of the verdicts; the per-world intervals have confidence ``1 - alpha``, the
        adjusted ones the level that matches ``correction``.
    correction:
        ``"holm"`` (default), ``"bh"`` (Benjamini-Hochberg) or ``"none"``, across the worlds of each metric.
    labels:
        Names of A and B for statements and plots.
    paired_by:
        None: the campaigns are independent (Welch). Otherwise what makes run ``(world, i)`` of A and of
        B a pair, in words (``"replay of /data/c1"``): the tests are paired on the runs present in both.

    Returns
    -------
    Comparison

    Raises
    ------
    ValueError
        A missing column, a non-finite error, a run index twice in one world of a paired comparison, a bad
        ``alpha`` or ``correction``, or no world in common.
    """
    if not (0.0 < alpha < 1.0):
        raise ValueError(f"alpha must be strictly between 0 and 1, got {alpha}")
    if correction not in ("holm", "bh", "none"):
        raise ValueError(f"unknown correction {correction!r}; use 'holm', 'bh' or 'none'")
    paired = paired_by is not None
    values_a = {m: check_metric(a, m, "campaign A") for m in metrics}
    values_b = {m: check_metric(b, m, "campaign B") for m in metrics}
    worlds_a, worlds_b = a["world"].astype(str).to_numpy(), b["world"].astype(str).to_numpy()
    in_b = set(worlds_b)
    common = [w for w in dict.fromkeys(worlds_a) if w in in_b]  # campaign A's order
    if not common:
        raise ValueError("campaigns A and B have no world in common")
    runs_a, runs_b = a["run"].to_numpy(dtype=np.int64), b["run"].to_numpy(dtype=np.int64)
    tables, overall, intervals = [], {}, {}
    for metric in metrics:
        rows = []
        for world in common:
            ia, ib = worlds_a == world, worlds_b == world
            rows.append(
                _world_row(
                    world,
                    metric,
                    values_a[metric][ia],
                    runs_a[ia],
                    values_b[metric][ib],
                    runs_b[ib],
                    1.0 - alpha,
                    paired,
                )
            )
        table = pd.DataFrame(rows)
        table.insert(table.columns.get_loc("p") + 1, "p_adjusted", adjust_pvalues(table["p"].to_numpy(), correction))
        table.insert(
            table.columns.get_loc("wilcoxon_p") + 1,
            "wilcoxon_p_adjusted",
            adjust_pvalues(table["wilcoxon_p"].to_numpy(), correction),
        )
        level = interval_level(alpha, correction, table["p_adjusted"].to_numpy())
        low, high = _adjusted_intervals(table, level)
        at = table.columns.get_loc("ci_high") + 1
        table.insert(at, "ci_adj_low", low)
        table.insert(at + 1, "ci_adj_high", high)
        table.insert(at + 2, "ci_adj_level", level.confidence)
        table.insert(at + 3, "verdict", [_verdict(r, alpha) for _, r in table.iterrows()])
        overall[metric] = _overall(metric, table, alpha, correction, labels, paired)
        intervals[metric] = level
        tables.append(table)
    return Comparison(
        table=pd.concat(tables, ignore_index=True),
        overall=overall,
        intervals=intervals,
        alpha=alpha,
        correction=correction,
        labels=(str(labels[0]), str(labels[1])),
        pairing=f"paired ({paired_by})" if paired else "unpaired (Welch)",
        only_a=tuple(sorted(set(worlds_a) - set(common))),
        only_b=tuple(sorted(set(worlds_b) - set(common))),
    )


def world_pair_traps(runs: pd.DataFrame, metric: str = "eps_t", *, alpha: float = 0.05) -> pd.DataFrame:
    """The paper's Fig. 6 trap between every pair of worlds of one campaign.

    For worlds ``L`` (lower mean error) and ``H`` (higher), single runs mislead when a run of ``L`` has a
    larger error than a run of ``H``.

    Parameters
    ----------
    runs:
        One row per finished run, columns ``world``, ``run``, ``metric``.
    metric:
        ``"eps_t"`` (m) or ``"eps_r"`` (rad).
    alpha:
        Level of the Welch test of the two means (uncorrected), reported as ``means_differ``.

    Returns
    -------
    pandas.DataFrame
        One row per unordered pair of worlds, columns ``world_low``, ``world_high``, ``mean_low``,
        ``mean_high``, ``p`` (Welch, two-sided), ``means_differ`` (``p <= alpha``), ``reversed_fraction``,
        ``run_low``, ``run_high`` (``run`` indexes of the most misleading pair), ``value_low``,
        ``value_high`` and ``reversed_by`` (``value_low - value_high``); sorted by ``reversed_by``,
        largest first. Pairs of equal means are left out.
    """
    values = check_metric(runs, metric)
    worlds = runs["world"].astype(str).to_numpy()
    run_index = runs["run"].to_numpy()
    groups = {w: (values[worlds == w], run_index[worlds == w]) for w in sorted(set(worlds))}
    rows = []
    for w1, w2 in combinations(groups, 2):
        if groups[w1][0].mean() == groups[w2][0].mean():
            continue
        low, high = (w1, w2) if groups[w1][0].mean() < groups[w2][0].mean() else (w2, w1)
        (vl, rl), (vh, rh) = groups[low], groups[high]
        rev = reversal(vl, vh)
        p = welch(vl, vh).p
        rows.append(
            {
                "world_low": low,
                "world_high": high,
                "mean_low": float(vl.mean()),
                "mean_high": float(vh.mean()),
                "p": p,
                "means_differ": bool(p <= alpha),
                "reversed_fraction": rev.fraction,
                "run_low": int(rl[rev.i_low]),
                "run_high": int(rh[rev.i_high]),
                "value_low": float(vl[rev.i_low]),
                "value_high": float(vh[rev.i_high]),
                "reversed_by": rev.reversed_by,
            }
        )
    columns = [
        "world_low",
        "world_high",
        "mean_low",
        "mean_high",
        "p",
        "means_differ",
        "reversed_fraction",
        "run_low",
        "run_high",
        "value_low",
        "value_high",
        "reversed_by",
    ]
    table = pd.DataFrame(rows, columns=columns)
    return table.sort_values("reversed_by", ascending=False, kind="stable").reset_index(drop=True)


def comparison_notes(comparison: Comparison) -> list[str]:
    """What a reader of a comparison should know beyond its table, one sentence each.

    Runs left out of the paired tests (no partner in the other campaign); worlds where the Wilcoxon
    check disagrees with the paired t-test at ``alpha`` (both corrected); worlds that Holm's step-down
    calls significant although their simultaneous (Bonferroni) interval reaches 0.
    """
    notes = []
    alpha = comparison.alpha
    first = comparison.for_metric(comparison.table["metric"].iloc[0]) if len(comparison.table) else None
    if comparison.paired and first is not None:
        left = first[(first["left_out_a"] > 0) | (first["left_out_b"] > 0)]
        if len(left):
            name_a, name_b = comparison.labels
            parts = [
                f"{r['world']} {r['left_out_a']} of {name_a}, {r['left_out_b']} of {name_b}" for _, r in left.iterrows()
            ]
            notes.append(
                f"Runs without a partner in the other campaign, left out of the paired tests: {'; '.join(parts)}."
            )
    for metric in dict.fromkeys(comparison.table["metric"]):
        rows = comparison.for_metric(metric)
        for _, r in rows.iterrows():
            if comparison.paired and np.isfinite(r["p_adjusted"]) and np.isfinite(r["wilcoxon_p_adjusted"]):
                t_says, w_says = r["p_adjusted"] <= alpha, r["wilcoxon_p_adjusted"] <= alpha
                if t_says != w_says:
                    floor = 2.0 / 2.0 ** int(r["n_a"])
                    notes.append(
                        f"{r['world']}, {metric}: the paired t-test says {r['verdict']} (p adj = {r['p_adjusted']:.3g}) "
                        f"but the Wilcoxon signed-rank check {'does' if w_says else 'does not'} "
                        f"(p adj = {r['wilcoxon_p_adjusted']:.3g}"
                        + (f"; with {int(r['n_a'])} pairs it cannot go below {floor:.3g}" if floor > alpha else "")
                        + ")."
                    )
            if (
                comparison.correction == "holm"
                and r["verdict"] in (A_BETTER, B_BETTER)
                and r["ci_adj_low"] <= 0.0 <= r["ci_adj_high"]
            ):
                notes.append(
                    f"{r['world']}, {metric}: significant by Holm's step-down (p adj = {r['p_adjusted']:.3g}) although its "
                    "simultaneous interval reaches 0: Holm's later steps test at alpha/(m-1), ..., alpha, the "
                    "intervals at alpha/m."
                )
    return notes
