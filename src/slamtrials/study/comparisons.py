"""Paired comparisons between neighbouring values of each axis of a study.

For an axis with values ``v_0, v_1, ...`` (in the config's order) and each combination of the other
axes' values, cell ``(v_i, others)`` (A) is compared with cell ``(v_{i+1}, others)`` (B), world by world
and metric by metric, with :func:`slamtrials.report.compare.compare_campaigns`: the cells of a world
share their seeds, so run ``k`` of A and run ``k`` of B are a pair (the paired t-test on the run-by-run
differences ``B - A``, with the Wilcoxon signed-rank check). Should a seed differ (a folder made by
another version), that comparison falls back to Welch's test and says so.

The multiple-comparison correction of ``compare`` (Holm by default, or Benjamini-Hochberg, or none) is
applied over the whole study, per metric: every (axis step, other values, world) comparison of one
metric is one family, so the more cells and worlds a study has, the stronger the evidence a verdict
needs. The intervals beside the verdicts are adjusted the same way
(:func:`slamtrials.report.combine.interval_level`).

Identical comparisons are left out of the family (:data:`IDENTICAL_RULE`): where every paired
difference is exactly 0 (the setting changed nothing that these runs saw, e.g. a 15 m laser in a
building with no wall farther away, and the shared seeds made the runs the same bit for bit), the test
has ``p = 1`` and carries no evidence either way; counting it would only weaken the correction of the
comparisons that do differ. Such a row keeps ``p = 1`` as its adjusted p-value, the verdict "no
significant difference" and ``identical`` True; ``m`` (Holm's, Benjamini-Hochberg's and the intervals')
counts the other comparisons of its metric.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from scipy import stats

from slamtrials.report.combine import IntervalLevel, interval_level
from slamtrials.report.compare import (
    A_BETTER,
    B_BETTER,
    NO_DIFFERENCE,
    TOO_FEW,
    Correction,
    adjust_pvalues,
    compare_campaigns,
)
from slamtrials.report.tables import METRICS
from slamtrials.study.cells import Cell
from slamtrials.study.config import value_text

__all__ = ["PAIRED_BY", "IDENTICAL_RULE", "neighbour_pairs", "compare_neighbours", "seeds_agree", "identical_rows"]

#: What makes run ``k`` of two cells of one world a pair.
PAIRED_BY = "cells of one study share their seeds"

#: The rule on identical comparisons, as the report states it.
IDENTICAL_RULE = (
    "Comparisons whose paired runs are identical (every paired difference exactly 0, p = 1) carry no evidence "
    "and are left out of the family: m counts the others."
)


def neighbour_pairs(cells: Sequence[Cell], axes: Mapping[str, Sequence]) -> list[tuple[str, str, Cell, Cell]]:
    """``(axis key, the other axes' values as text, cell A, cell B)`` for every step between neighbouring
    values of an axis among the product cells (named combinations are not on the grid)."""
    grid = {tuple(value_text(v) for _, v in c.settings): c for c in cells if not c.combination}
    keys = list(axes)
    pairs = []
    for position, key in enumerate(keys):
        values = [value_text(v) for v in axes[key]]
        others = [[value_text(v) for v in axes[k]] for k in keys if k != key]
        for rest in _product(others):
            label = ", ".join(f"{k}={v}" for k, v in zip([k for k in keys if k != key], rest, strict=True))
            for low, high in zip(values, values[1:], strict=False):
                a = grid.get(_insert(rest, position, low))
                b = grid.get(_insert(rest, position, high))
                if a is not None and b is not None:
                    pairs.append((key, label, a, b))
    return pairs


def _product(lists: list[list[str]]) -> list[tuple[str, ...]]:
    out: list[tuple[str, ...]] = [()]
    for values in lists:
        out = [(*head, v) for head in out for v in values]
    return out


def _insert(rest: tuple[str, ...], position: int, value: str) -> tuple[str, ...]:
    return (*rest[:position], value, *rest[position:])


def seeds_agree(a: pd.DataFrame, b: pd.DataFrame) -> bool:
    """Whether every ``(world, run)`` present in both run tables has the same seed in both."""
    keys = ["world", "run"]
    both = pd.merge(a[[*keys, "seed"]], b[[*keys, "seed"]], on=keys, suffixes=("_a", "_b"))
    return bool((both["seed_a"] == both["seed_b"]).all())


def identical_rows(table: pd.DataFrame) -> np.ndarray:
    """``[rows]`` bool: the paired comparisons of at least 2 pairs whose every difference is exactly 0."""
    if table.empty:
        return np.zeros(0, dtype=bool)
    std = table["std_difference"].to_numpy(dtype=np.float64)
    difference = table["difference"].to_numpy(dtype=np.float64)
    pairs = table["n_a"].to_numpy(dtype=np.float64)
    return ((table["test"] == "paired t").to_numpy() & (pairs >= 2) & (std == 0.0) & (difference == 0.0)).astype(bool)


def _verdict(p_adjusted: float, difference: float, alpha: float) -> str:
    if not math.isfinite(p_adjusted):
        return TOO_FEW
    if p_adjusted > alpha or difference == 0:
        return NO_DIFFERENCE
    return B_BETTER if difference < 0 else A_BETTER


def compare_neighbours(
    cells: Sequence[Cell],
    axes: Mapping[str, Sequence],
    runs: Mapping[str, pd.DataFrame],
    *,
    alpha: float = 0.05,
    correction: Correction = "holm",
) -> tuple[pd.DataFrame, dict[str, IntervalLevel]]:
    """Every neighbour comparison of the study (see the module docstring).

    Parameters
    ----------
    cells, axes:
        The study's cells and axes.
    runs:
        ``{cell name: its finished runs}`` (columns ``world``, ``run``, ``seed``, ``eps_t``, ``eps_r``);
        cells without finished runs are left out.
    alpha, correction:
        As for ``compare``.

    Returns
    -------
    (pandas.DataFrame, dict)
        One row per (axis step, other values, world, metric): ``axis``, ``others``, ``cell_a``,
        ``cell_b``, ``value_a``, ``value_b`` and the columns of
        :attr:`slamtrials.report.compare.Comparison.table` (``difference`` is ``B - A``; ``p_adjusted``,
        ``wilcoxon_p_adjusted``, ``ci_adj_*`` and ``verdict`` over the study's family of its metric,
        identical comparisons left out of it), ``identical`` (see the module docstring); and ``{metric: the
        adjusted intervals' level}``.
    """
    tables = []
    for key, others, a, b in neighbour_pairs(cells, axes):
        runs_a, runs_b = runs.get(a.name), runs.get(b.name)
        if runs_a is None or runs_b is None or runs_a.empty or runs_b.empty:
            continue
        if not set(runs_a["world"]) & set(runs_b["world"]):
            continue
        paired_by = PAIRED_BY if seeds_agree(runs_a, runs_b) else None
        comparison = compare_campaigns(
            runs_a, runs_b, alpha=alpha, correction="none", labels=(a.name, b.name), paired_by=paired_by
        )
        table = comparison.table.copy()
        table.insert(0, "axis", key)
        table.insert(1, "others", others)
        table.insert(2, "cell_a", a.name)
        table.insert(3, "cell_b", b.name)
        table.insert(4, "value_a", value_text(a.value(key)))
        table.insert(5, "value_b", value_text(b.value(key)))
        tables.append(table)
    if not tables:
        return pd.DataFrame(), {}
    table = pd.concat(tables, ignore_index=True)
    table["identical"] = identical_rows(table)
    levels: dict[str, IntervalLevel] = {}
    for metric in METRICS:
        rows = table.index[table["metric"] == metric]
        if len(rows) == 0:
            continue
        identical = table.loc[rows, "identical"].to_numpy(dtype=bool)
        family = np.where(identical, np.nan, table.loc[rows, "p"].to_numpy(dtype=np.float64))
        p_adj = adjust_pvalues(family, correction)
        level = interval_level(alpha, correction, p_adj, unit="comparison")
        p_adj[identical] = 1.0
        table.loc[rows, "p_adjusted"] = p_adj
        wilcoxon = np.where(identical, np.nan, table.loc[rows, "wilcoxon_p"].to_numpy(dtype=np.float64))
        wilcoxon_adj = adjust_pvalues(wilcoxon, correction)
        wilcoxon_adj[identical] = 1.0
        table.loc[rows, "wilcoxon_p_adjusted"] = wilcoxon_adj
        levels[metric] = level
        diff, se, dof = (table.loc[rows, c].to_numpy(dtype=np.float64) for c in ("difference", "se", "dof"))
        half = np.full(len(rows), np.nan)
        ok = np.isfinite(se) & np.isfinite(dof)
        half[ok] = stats.t.ppf(0.5 + level.confidence / 2.0, dof[ok]) * se[ok]
        table.loc[rows, "ci_adj_low"] = diff - half
        table.loc[rows, "ci_adj_high"] = diff + half
        table.loc[rows, "ci_adj_level"] = level.confidence
        table.loc[rows, "verdict"] = [_verdict(p, d, alpha) for p, d in zip(p_adj, diff, strict=True)]
    return table, levels
