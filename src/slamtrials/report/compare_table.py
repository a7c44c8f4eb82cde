"""The comparison page's per-world table of one metric (``<table id="comparison-table-<metric>">``): the
means of both campaigns, their difference with corrected and unadjusted intervals, the p-values, the verdict
and the share of single-run pairs that reverse the means (:class:`slamtrials.report.compare.Comparison`)."""

from __future__ import annotations

import math

import pandas as pd

from slamtrials.report import html as h
from slamtrials.report.compare import A_BETTER, B_BETTER, Comparison
from slamtrials.report.tables import SYMBOLS, UNITS

__all__ = ["comparison_table"]


def comparison_table(comparison: Comparison, metric: str) -> str:
    """The table of ``metric`` (``eps_t`` or ``eps_r``): one row per compared world, green where B is better,
    red where A is; a paired comparison shows the pairs, the Wilcoxon check and the correlation of the runs'
    errors, an unpaired one the runs of each campaign."""
    paired = comparison.paired
    digits = 3 if metric == "eps_t" else 4
    rows, classes = [], []
    for _, r in comparison.for_metric(metric).iterrows():
        rows.append(_row(r, digits, paired))
        classes.append("good" if r["verdict"] == B_BETTER else ("bad" if r["verdict"] == A_BETTER else None))
    name_a, name_b = comparison.labels
    test = "paired t" if paired else "Welch"
    level = comparison.intervals[metric]
    header = [
        "world",
        *(["pairs"] if paired else [f"n {name_a}", f"n {name_b}"]),
        f"mean {name_a}",
        f"mean {name_b}",
        f"{name_b} \u2212 {name_a}",
        f"CI: {level.label}",
        f"CI: {1 - comparison.alpha:.0%} this world alone (unadjusted)",
        f"p ({test})",
        f"p ({test}, {comparison.correction})",
        *([f"p (Wilcoxon check, {comparison.correction})"] if paired else []),
        *(["r of the paired errors"] if paired else []),
        "verdict",
        "single-run pairs reversed",
    ]
    how = (
        "the paired t-test on the run-by-run differences (runs paired by world and index), with the Wilcoxon "
        "signed-rank test of the same differences as a check"
        if paired
        else "Welch's t-test (the runs of the two campaigns are independent)"
    )
    return h.table(
        header,
        rows,
        id=f"comparison-table-{metric}",
        row_classes=classes,
        caption=f"{SYMBOLS[metric]} ({UNITS[metric]}), lower is better; {comparison.pairing}: per world the "
        f"difference of mean errors by {how}; p-values corrected for {len(rows)} comparisons "
        f"({comparison.correction}) and the first interval corrected alike ({level.label}); the second holds for "
        f"one world alone. Verdict on the corrected p at \u03b1 = {comparison.alpha:g}."
        + (
            " r: the correlation of a run's errors in the two campaigns; pairing narrows the interval only where it is positive."
            if paired
            else ""
        ),
    )


def _row(r: pd.Series, digits: int, paired: bool) -> list:
    """The cells of one world's row of :attr:`Comparison.table`; errors with ``digits`` decimals."""
    return [
        r["world"],
        *([h.Cell(str(r["n_a"]), numeric=True)] if paired else []),
        *([] if paired else [h.Cell(str(r["n_a"]), numeric=True), h.Cell(str(r["n_b"]), numeric=True)]),
        h.number_cell(r["mean_a"], digits),
        h.number_cell(r["mean_b"], digits),
        h.number_cell(r["difference"], digits),
        _interval(r["ci_adj_low"], r["ci_adj_high"], digits),
        _interval(r["ci_low"], r["ci_high"], digits),
        h.number_cell(r["p"], 4),
        h.number_cell(r["p_adjusted"], 4),
        *([h.number_cell(r["wilcoxon_p_adjusted"], 4)] if paired else []),
        *([h.number_cell(r["correlation"], 2)] if paired else []),
        r["verdict"],
        h.Cell(
            h.fmt_number(r["trap_fraction"] * 100, 0) + " %" if math.isfinite(r["trap_fraction"]) else "-",
            numeric=True,
        ),
    ]


def _interval(low: float, high: float, digits: int) -> h.Cell:
    """``[low, high]`` with ``digits`` decimals, right-aligned."""
    return h.Cell(f"[{h.fmt_number(low, digits)}, {h.fmt_number(high, digits)}]", numeric=True)
