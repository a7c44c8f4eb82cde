"""The study's figures, each drawn on a given matplotlib Axes.

* :func:`draw_error_against_axis`: a world's mean error (``eps_t`` m or ``eps_r`` rad) with its
  interval at each value of one axis, one line per combination of the other axes' values;
* :func:`draw_cost_against_error`: a world's cells as points of mean cost per run (SLAM CPU s or peak
  MiB) against mean error with its interval, each labelled with its cell.

Values of an axis are drawn at equal steps in the config's order (they may be names: profiles,
algorithms). Artists carry a ``gid``: ``"means"`` for the lines and points.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

__all__ = ["draw_error_against_axis", "draw_cost_against_error", "UNITS", "SYMBOLS"]

UNITS = {"eps_t": "m", "eps_r": "rad", "slam_cpu_s_mean": "s", "slam_peak_mib_mean": "MiB"}
SYMBOLS = {
    "eps_t": "\u03b5t",
    "eps_r": "\u03b5r",
    "slam_cpu_s_mean": "SLAM CPU",
    "slam_peak_mib_mean": "SLAM peak memory",
}


def _yerr(rows: pd.DataFrame, metric: str) -> np.ndarray:
    mean = rows[f"{metric}_mean"].to_numpy(dtype=np.float64)
    low = rows[f"{metric}_ci_low"].to_numpy(dtype=np.float64)
    high = rows[f"{metric}_ci_high"].to_numpy(dtype=np.float64)
    return np.nan_to_num(np.vstack([mean - low, high - mean]), nan=0.0)


def draw_error_against_axis(ax, rows: pd.DataFrame, key: str, values: Sequence[str], metric: str) -> int:
    """Mean ``metric`` with its interval against the values of axis ``key``; return the lines drawn.

    Parameters
    ----------
    ax:
        The Axes.
    rows:
        One world's rows of :func:`slamtrials.study.tables.cells_table` (product cells), with a column
        ``others`` naming the other axes' values (the line each row belongs to).
    key, values:
        The axis and its values as text, in order (the x positions).
    metric:
        ``"eps_t"`` or ``"eps_r"``.
    """
    position = {v: i for i, v in enumerate(values)}
    groups = list(dict.fromkeys(rows["others"]))
    offsets = np.linspace(-0.08, 0.08, len(groups)) if len(groups) > 1 else np.zeros(1)
    drawn = 0
    for offset, group in zip(offsets, groups, strict=True):
        here = rows[rows["others"] == group]
        here = here.assign(_x=here[key].map(position)).dropna(subset=["_x", f"{metric}_mean"])
        here = here.sort_values("_x", kind="stable")
        if here.empty:
            continue
        ax.errorbar(
            here["_x"].to_numpy(dtype=np.float64) + offset,
            here[f"{metric}_mean"].to_numpy(dtype=np.float64),
            yerr=_yerr(here, metric),
            marker="o",
            capsize=3,
            label=group or None,
            gid="means",
        )
        drawn += 1
    ax.set_xticks(np.arange(len(values)), labels=list(values))
    ax.set_xlim(-0.5, len(values) - 0.5)
    ax.set_xlabel(key)
    ax.set_ylabel(f"mean {SYMBOLS[metric]} ({UNITS[metric]})")
    if drawn > 1:
        ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    return drawn


def draw_cost_against_error(ax, rows: pd.DataFrame, cost: str, metric: str = "eps_t") -> int:
    """Each cell of one world at (mean ``cost`` per run, mean ``metric`` with its interval); return the
    points drawn (cells without that cost measured are left out).

    ``rows``: one world's rows of :func:`slamtrials.study.tables.cells_table`; ``cost``:
    ``"slam_cpu_s_mean"`` (s) or ``"slam_peak_mib_mean"`` (MiB).
    """
    here = rows.dropna(subset=[cost, f"{metric}_mean"])
    if here.empty:
        ax.text(0.5, 0.5, "no cost recorded", ha="center", va="center", transform=ax.transAxes)
        return 0
    x = here[cost].to_numpy(dtype=np.float64)
    ax.errorbar(
        x,
        here[f"{metric}_mean"].to_numpy(dtype=np.float64),
        yerr=_yerr(here, metric),
        fmt="o",
        capsize=3,
        gid="means",
    )
    for xi, yi, name in zip(x, here[f"{metric}_mean"], here["cell"], strict=True):
        ax.annotate(str(name), (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.margins(x=0.25)  # room for the labels
    ax.set_xlabel(f"{SYMBOLS[cost]} per run ({UNITS[cost]})")
    ax.set_ylabel(f"mean {SYMBOLS[metric]} ({UNITS[metric]})")
    ax.grid(True, alpha=0.3)
    return len(here)
