"""Per-world tables of a campaign's runs: the paper's Table I, with confidence intervals and outliers.

Input is a pandas DataFrame ``runs`` with one row per finished run and at least the columns ``world``
(str), ``run`` (int run index), ``eps_t`` (m) and ``eps_r`` (rad); any other column is ignored.

The outlier rule (shared with :func:`slamtrials.report.campaign_figures.draw_all_runs`): within one
world, a run is an outlier of a metric when its value lies beyond Tukey's fences, more than 1.5
interquartile ranges below the first or above the third quartile, the quartiles taken by linear
interpolation (``numpy.percentile``'s default, the same matplotlib's box plot uses for its whiskers).

The metric's share of the between-run variance (:func:`metric_shares`): per world, the runs' mean squared
standard error over the variance of their errors (:func:`slamtrials.metric.metric_noise_share`), from
the columns ``se_t`` and ``se_r`` (the catalog's details; absent for runs of earlier versions).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from slamtrials.metric.noiseshare import metric_noise_share
from slamtrials.metric.quantiles import Distribution
from slamtrials.metric.stats import environment_stats

__all__ = [
    "METRICS",
    "UNITS",
    "SYMBOLS",
    "OUTLIER_IQR",
    "require_columns",
    "column_values",
    "finite_mean",
    "check_metric",
    "outlier_mask",
    "world_outliers",
    "world_summary",
    "paper_table",
    "metric_shares",
    "STANDARD_ERRORS",
    "NOISE_SHARE_LIMIT",
    "share_percent",
]

#: The per-run error columns: translational (m) and rotational (rad).
METRICS = ("eps_t", "eps_r")
#: The unit of each metric.
UNITS = {"eps_t": "m", "eps_r": "rad"}
#: How the pages write each metric: \u03b5t, \u03b5r.
SYMBOLS = {"eps_t": "\u03b5t", "eps_r": "\u03b5r"}
#: Tukey's fence factor of the outlier rule.
OUTLIER_IQR = 1.5
#: The column of each metric's per-run standard error (m, rad).
STANDARD_ERRORS = {"eps_t": "se_t", "eps_r": "se_r"}
#: Below this share of the between-run variance, the metric's own noise is small against the runs' differences.
NOISE_SHARE_LIMIT = 0.10


def require_columns(runs: pd.DataFrame, columns: Iterable[str], what: str = "runs") -> None:
    """Raise ``ValueError`` naming the first of ``columns`` that ``runs`` lacks."""
    if not isinstance(runs, pd.DataFrame):
        raise TypeError(f"{what} must be a pandas DataFrame, got {type(runs).__name__}")
    for column in columns:
        if column not in runs.columns:
            raise ValueError(f"{what} is missing the column '{column}' (it has: {', '.join(map(str, runs.columns))})")


def column_values(runs: pd.DataFrame, column: str) -> NDArray[np.float64]:
    """float64 ``[R]``: ``column`` of every run as a number (NaN where missing or not a number; an absent
    column is all NaN), for the figures a run may not have recorded (cost, map quality)."""
    if column not in runs.columns:
        return np.full(len(runs), np.nan)
    return pd.to_numeric(runs[column], errors="coerce").to_numpy(dtype=np.float64, na_value=np.nan)


def finite_mean(values: NDArray[np.float64]) -> float:
    """The mean of the finite values of ``values`` (float64 ``[N]``); NaN when none is finite."""
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if len(finite) else math.nan


def check_metric(runs: pd.DataFrame, metric: str, what: str = "runs") -> NDArray[np.float64]:
    """The values ``[R]`` of column ``metric`` as float64, after checking that every one is finite.

    Raises
    ------
    ValueError
        ``metric`` is not one of :data:`METRICS`, the column (or ``world`` / ``run``) is missing, or a value
        is not a finite number (the message names the world and run).
    """
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
    require_columns(runs, ("world", "run", metric), what)
    values = pd.to_numeric(runs[metric], errors="coerce").to_numpy(dtype=np.float64, na_value=np.nan)
    bad = ~np.isfinite(values)
    if bad.any():
        row = runs.iloc[int(np.argmax(bad))]
        raise ValueError(f"{what}: world {row['world']!r} run {row['run']} has a non-finite {metric} ({row[metric]!r})")
    return values


def outlier_mask(values: ArrayLike, factor: float = OUTLIER_IQR) -> NDArray[np.bool_]:
    """Which of the values ``[R]`` of one world lie beyond Tukey's fences ``Q1 - f IQR``, ``Q3 + f IQR``.

    Quartiles by linear interpolation; an empty input gives an empty mask.
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if len(v) == 0:
        return np.zeros(0, dtype=bool)
    q1, q3 = np.percentile(v, [25.0, 75.0])
    spread = factor * (q3 - q1)
    return (v < q1 - spread) | (v > q3 + spread)


def world_outliers(runs: pd.DataFrame, metric: str = "eps_t") -> pd.Series:
    """Boolean Series (aligned with ``runs.index``): the run is an outlier of ``metric`` within its world."""
    values = pd.Series(check_metric(runs, metric), index=runs.index)
    return (
        values.groupby(runs["world"].astype(str), sort=False)
        .transform(lambda v: outlier_mask(v.to_numpy()))
        .astype(bool)
    )


def world_summary(runs: pd.DataFrame, confidence: float = 0.99, distribution: Distribution = "t") -> pd.DataFrame:
    """The paper's Table I for every world: runs, mean, spread and confidence interval of the errors.

    Parameters
    ----------
    runs:
        One row per finished run with columns ``world``, ``run``, ``eps_t`` (m), ``eps_r`` (rad).
    confidence, distribution:
        Confidence level and quantile of the intervals of the means (Student t by default; use the
        campaign's run-count rule's, :func:`slamtrials.metric.stats.environment_stats`).

    Returns
    -------
    pandas.DataFrame
        One row per world, sorted by world, flat CSV-friendly columns: ``world``, ``runs``, then for
        ``m`` in ``eps_t``, ``eps_r``: ``m_mean``, ``m_std`` (divisor ``n - 1``), ``m_std_population``
        (divisor ``n``, the paper's printed form), ``m_ci_low``, ``m_ci_high``, ``m_half_width``,
        ``m_min``, ``m_max``, ``m_outliers`` (count by :func:`outlier_mask`); and ``confidence``.
        Std and interval are NaN for a world of one run.

    Raises
    ------
    ValueError
        A missing column or a non-finite error.
    """
    values = {metric: check_metric(runs, metric) for metric in METRICS}
    worlds = runs["world"].astype(str).to_numpy()
    rows = []
    for world in sorted(set(worlds)):
        here = worlds == world
        row: dict[str, object] = {"world": world, "runs": int(here.sum())}
        for metric in METRICS:
            v = values[metric][here]
            stats = environment_stats(v, confidence=confidence, distribution=distribution)
            row.update(
                {
                    f"{metric}_mean": stats.mean,
                    f"{metric}_std": stats.std_sample,
                    f"{metric}_std_population": stats.std_population,
                    f"{metric}_ci_low": stats.ci_low,
                    f"{metric}_ci_high": stats.ci_high,
                    f"{metric}_half_width": stats.half_width,
                    f"{metric}_min": float(v.min()),
                    f"{metric}_max": float(v.max()),
                    f"{metric}_outliers": int(outlier_mask(v).sum()),
                }
            )
        row["confidence"] = float(confidence)
        rows.append(row)
    columns = ["world", "runs"] + [
        f"{m}_{s}"
        for m in METRICS
        for s in ("mean", "std", "std_population", "ci_low", "ci_high", "half_width", "min", "max", "outliers")
    ]
    return pd.DataFrame(rows, columns=columns + ["confidence"])


def paper_table(summary: pd.DataFrame, metric: str = "eps_t", *, population: bool = False) -> pd.DataFrame:
    """Table I laid out as printed: rows ``average`` and ``std dev``, one column per world.

    Parameters
    ----------
    summary:
        The output of :func:`world_summary`.
    metric:
        ``"eps_t"`` (m) or ``"eps_r"`` (rad).
    population:
        Use the standard deviation with divisor ``n`` (as the paper's Definition III.3) instead of ``n - 1``.
    """
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
    std = f"{metric}_std_population" if population else f"{metric}_std"
    require_columns(summary, ("world", f"{metric}_mean", std), "summary")
    table = summary.set_index("world")[[f"{metric}_mean", std]].T
    table.index = ["average", "std dev"]
    table.columns.name = None
    return table


def metric_shares(runs: pd.DataFrame, metric: str = "eps_t") -> pd.Series:
    """Per world, the metric's share of the between-run variance of ``metric``: ``mean(se^2) / var(eps)``.

    Parameters
    ----------
    runs:
        One row per finished run with ``world``, ``run``, ``metric`` and, when recorded, its standard error
        column (:data:`STANDARD_ERRORS`: ``se_t`` for ``eps_t``, ``se_r`` for ``eps_r``).

    Returns
    -------
    pandas.Series
        float64 indexed by world (sorted by world): the share (0.05 is 5 %), NaN where a run of the world has
        no standard error (runs of earlier versions, or a missing column), for fewer than 2 runs, or when the
        runs' errors do not vary (:func:`slamtrials.metric.metric_noise_share`).
    """
    values = check_metric(runs, metric)
    column = STANDARD_ERRORS[metric]
    if column in runs.columns:
        errors = pd.to_numeric(runs[column], errors="coerce").to_numpy(dtype=np.float64, na_value=np.nan)
    else:
        errors = np.full(len(runs), np.nan)
    worlds = runs["world"].astype(str).to_numpy()
    names = sorted(set(worlds.tolist()))
    shares = [metric_noise_share(values[worlds == w], errors[worlds == w]) for w in names]
    return pd.Series(shares, index=pd.Index(names, name="world"), dtype="float64", name=f"{metric}_metric_share")


def share_percent(share: float) -> str:
    """A share (0.00019) as a percentage with two significant digits (``0.019 %``), whole percent from
    10 % up (``12 %``, ``150 %``), ``< 0.001 %`` below that, so that a small share never reads as
    ``0.0 %``."""
    percent = 100.0 * float(share)
    if percent == 0.0:
        return "0 %"
    if abs(percent) < 0.001:
        return "< 0.001 %"
    if abs(percent) >= 10.0:
        return f"{percent:.0f} %"
    digits = max(0, 1 - int(np.floor(np.log10(abs(percent)))))
    return f"{percent:.{digits}f} %"
