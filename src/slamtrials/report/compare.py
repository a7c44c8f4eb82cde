"""Statistical comparison of two campaigns (A and B, e.g. two SLAM algorithms on the same worlds).

Per world and metric (``eps_t`` in m, ``eps_r`` in rad; lower is better):

- the difference of the mean errors ``B - A`` with a Welch confidence interval (standard error
  ``sqrt(s_A^2/n_A + s_B^2/n_B)``, Welch-Satterthwaite degrees of freedom, Student-t quantile);
- the two-sided Welch t-test p-value (equal to ``scipy.stats.ttest_ind(b, a, equal_var=False)``);
- the p-values adjusted for multiple comparisons across the worlds of one metric (each metric is its own
  family): Holm-Bonferroni by default (controls the family-wise error rate), Benjamini-Hochberg on request
  (controls the false discovery rate), or none;
- a verdict at level ``alpha`` on the adjusted p-value: ``"A better"``, ``"B better"``,
  ``"no significant difference"``, or ``"too few runs"`` when either side has fewer than 2 runs.
  The intervals are per world at level ``1 - alpha`` and are not adjusted, so a world whose interval
  excludes 0 may still be "no significant difference" after the correction.

Overall, per metric: the counts of verdicts, and an exact two-sided **sign test** over worlds on the sign of
the per-world difference of means (worlds with equal means are dropped). Each world counts once, as the
paper's unit of evaluation is the environment; the test asks whether one campaign has the lower mean in
more worlds than chance would give, makes no assumption of normality or of a common effect size across
worlds (which a fixed-effects pooling would), and is not dominated by the worlds with many runs. It needs
at least 6 worlds to reach p < 0.05.

The trap of the paper's Fig. 6, made visible: comparing single runs can give the opposite verdict from
comparing means. For two samples ``x`` (lower mean) and ``y`` (higher mean) the *reversal fraction* is
the fraction of the pairs ``(x_i, y_j)`` with ``x_i > y_j`` (ties count as not reversed), and the *most
misleading pair* is ``(argmax x, argmin y)``, whose reversed difference ``max x - min y`` is the largest.
:func:`compare_campaigns` reports it for A vs B in every world; :func:`world_pair_traps` for every pair
of worlds of one campaign (the paper's case: a bad run of the easier world beats a good run of the
harder one).
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

from slamtrials.report.tables import METRICS, check_metric

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
    "compare_campaigns",
    "world_pair_traps",
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
    sign_test_p:
        Exact two-sided sign test over ``b_lower`` vs ``b_higher``.
    median_difference:
        Median over worlds of ``mean_B - mean_A`` (units of the metric).
    verdict:
        ``"A better"``, ``"B better"`` (sign test significant at ``alpha``) or ``"no consistent difference"``.
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
    sign_test_p: float
    median_difference: float
    verdict: str
    statement: str


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare_campaigns`.

    Attributes
    ----------
    table:
        One row per (world, metric), sorted by metric then world. Columns: ``world``, ``metric``, ``n_a``,
        ``n_b``, ``mean_a``, ``mean_b``, ``std_a``, ``std_b``, ``difference`` (``mean_b - mean_a``), ``se``,
        ``dof``, ``t``, ``p``, ``p_adjusted``, ``ci_low``, ``ci_high``, ``verdict``; and the Fig. 6 trap:
        ``trap_fraction`` (fraction of (run of A, run of B) pairs whose comparison contradicts the sign of
        the difference of means), ``trap_run_a``, ``trap_run_b`` (``run`` indexes of the most misleading
        pair), ``trap_value_a``, ``trap_value_b`` (their errors), ``trap_difference`` (``value_b - value_a``,
        of the opposite sign to ``difference`` when the pair is reversed).
    overall:
        ``{metric: OverallVerdict}``.
    alpha, correction, labels:
        The settings; ``labels`` name A and B in statements and plots.
    only_a, only_b:
        Worlds present in one campaign only (not compared).
    """

    table: pd.DataFrame
    overall: dict[str, OverallVerdict]
    alpha: float
    correction: str
    labels: tuple[str, str]
    only_a: tuple[str, ...]
    only_b: tuple[str, ...]

    def for_metric(self, metric: str) -> pd.DataFrame:
        """The rows of ``table`` of one metric, indexed from 0."""
        return self.table[self.table["metric"] == metric].reset_index(drop=True)


def _world_row(
    world: str, metric: str, a: NDArray, runs_a: NDArray, b: NDArray, runs_b: NDArray, confidence: float
) -> dict:
    w = welch(a, b, confidence=confidence)
    row = {
        "world": world,
        "metric": metric,
        "n_a": w.n_a,
        "n_b": w.n_b,
        "mean_a": w.mean_a,
        "mean_b": w.mean_b,
        "std_a": w.std_a,
        "std_b": w.std_b,
        "difference": w.difference,
        "se": w.se,
        "dof": w.dof,
        "t": w.t,
        "p": w.p,
        "ci_low": w.ci_low,
        "ci_high": w.ci_high,
    }
    if w.difference > 0:  # A has the lower mean: a B run below an A run contradicts it
        r = reversal(a, b)
        ia, ib = r.i_low, r.i_high
    else:
        r = reversal(b, a)
        ib, ia = r.i_low, r.i_high
    row.update(
        {
            "trap_fraction": r.fraction,
            "trap_run_a": int(runs_a[ia]),
            "trap_run_b": int(runs_b[ib]),
            "trap_value_a": float(a[ia]),
            "trap_value_b": float(b[ib]),
            "trap_difference": float(b[ib] - a[ia]),
        }
    )
    return row


def _verdict(row: pd.Series, alpha: float) -> str:
    if not np.isfinite(row["p_adjusted"]):
        return TOO_FEW
    if row["p_adjusted"] > alpha or row["difference"] == 0:
        return NO_DIFFERENCE
    return B_BETTER if row["difference"] < 0 else A_BETTER


def _overall(metric: str, rows: pd.DataFrame, alpha: float, labels: tuple[str, str]) -> OverallVerdict:
    counts = rows["verdict"].value_counts()
    lower, higher = int((rows["difference"] < 0).sum()), int((rows["difference"] > 0).sum())
    ties = len(rows) - lower - higher
    p = sign_test(lower, higher)
    median = float(rows["difference"].median()) if len(rows) else math.nan
    name_a, name_b = labels
    if p <= alpha and lower != higher:
        verdict = B_BETTER if lower > higher else A_BETTER
        winner = name_b if lower > higher else name_a
        head = f"{winner} is better overall in {metric}"
    else:
        verdict = "no consistent difference"
        head = f"no consistent difference in {metric}"
    statement = (
        f"{head}: {name_b} has the lower mean in {lower} and the higher in {higher} of {len(rows)} worlds "
        f"(sign test p = {p:.3g}); significant at {alpha:g} after correction: {name_a} better in "
        f"{int(counts.get(A_BETTER, 0))}, {name_b} better in {int(counts.get(B_BETTER, 0))}."
    )
    return OverallVerdict(
        metric,
        len(rows),
        int(counts.get(A_BETTER, 0)),
        int(counts.get(B_BETTER, 0)),
        int(counts.get(NO_DIFFERENCE, 0)),
        int(counts.get(TOO_FEW, 0)),
        lower,
        higher,
        ties,
        p,
        median,
        verdict,
        statement,
    )


def compare_campaigns(
    a: pd.DataFrame,
    b: pd.DataFrame,
    *,
    metrics: tuple[str, ...] = METRICS,
    alpha: float = 0.05,
    correction: Correction = "holm",
    labels: tuple[str, str] = ("A", "B"),
) -> Comparison:
    """Compare campaign B with campaign A world by world (see the module docstring for the method).

    Parameters
    ----------
    a, b:
        Runs of the two campaigns, one row per finished run, columns ``world``, ``run`` and the metrics.
    metrics:
        Which of ``"eps_t"`` (m), ``"eps_r"`` (rad) to compare.
    alpha:
        Significance level of the verdicts; the intervals have confidence ``1 - alpha``.
    correction:
        ``"holm"`` (default), ``"bh"`` (Benjamini-Hochberg) or ``"none"``, across the worlds of each metric.
    labels:
        Names of A and B for statements and plots.

    Returns
    -------
    Comparison

    Raises
    ------
    ValueError
        A missing column, a non-finite error, a bad ``alpha`` or ``correction``, or no world in common.
    """
    if not (0.0 < alpha < 1.0):
        raise ValueError(f"alpha must be strictly between 0 and 1, got {alpha}")
    if correction not in ("holm", "bh", "none"):
        raise ValueError(f"unknown correction {correction!r}; use 'holm', 'bh' or 'none'")
    values_a = {m: check_metric(a, m, "campaign A") for m in metrics}
    values_b = {m: check_metric(b, m, "campaign B") for m in metrics}
    worlds_a, worlds_b = a["world"].astype(str).to_numpy(), b["world"].astype(str).to_numpy()
    common = sorted(set(worlds_a) & set(worlds_b))
    if not common:
        raise ValueError("campaigns A and B have no world in common")
    runs_a, runs_b = a["run"].to_numpy(), b["run"].to_numpy()
    tables, overall = [], {}
    for metric in metrics:
        rows = []
        for world in common:
            ia, ib = worlds_a == world, worlds_b == world
            rows.append(
                _world_row(
                    world, metric, values_a[metric][ia], runs_a[ia], values_b[metric][ib], runs_b[ib], 1.0 - alpha
                )
            )
        table = pd.DataFrame(rows)
        table.insert(table.columns.get_loc("p") + 1, "p_adjusted", adjust_pvalues(table["p"].to_numpy(), correction))
        table.insert(table.columns.get_loc("ci_high") + 1, "verdict", [_verdict(r, alpha) for _, r in table.iterrows()])
        overall[metric] = _overall(metric, table, alpha, labels)
        tables.append(table)
    return Comparison(
        table=pd.concat(tables, ignore_index=True),
        overall=overall,
        alpha=alpha,
        correction=correction,
        labels=(str(labels[0]), str(labels[1])),
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
