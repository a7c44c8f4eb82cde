"""What the runs of a campaign cost, drawn on a given matplotlib Axes: one figure of a run (CPU time, time
per update, memory; :class:`slamtrials.cost.RunCost`) per world, every run a point and the world's mean a bar.

Run tables are pandas DataFrames with one row per finished run and the columns ``world`` and the figure's
column (``slam_cpu_s``, ``update_ms_median``, ...: the catalog's run details); runs without that figure
(NaN: not measured, or stored by an earlier version) are left out. Artists carry a ``gid``: ``"runs"``,
``"means"`` and, for :func:`draw_update_times`, ``"p90"``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from slamtrials.report.tables import column_values, require_columns

__all__ = ["draw_cost_per_world", "draw_update_times", "cost_values"]


def cost_values(runs: pd.DataFrame, column: str) -> NDArray[np.float64]:
    """The float64 values ``[R]`` of cost figure ``column`` (NaN where missing; an absent column is all NaN)."""
    return column_values(runs, column)


def _positions(names: NDArray, order: list[str]) -> NDArray[np.float64]:
    """x of every run: its world's index in ``order``, spread a little within the world."""
    x = np.full(len(names), np.nan)
    for i, world in enumerate(order):
        here = np.flatnonzero(names == world)
        if len(here) > 1:
            x[here] = i + np.linspace(-0.2, 0.2, len(here))
        else:
            x[here] = i
    return x


def _from_zero(ax, *values: NDArray[np.float64], headroom: float = 1.08) -> None:
    """The y axis from 0 to ``headroom`` times the largest finite value drawn."""
    finite = np.concatenate([v[np.isfinite(v)] for v in values]) if values else np.zeros(0)
    top = float(finite.max()) if finite.size else 1.0
    ax.set_ylim(0.0, top * headroom if top > 0 else 1.0)


#: Room above the largest value for a legend in the upper right corner, clear of the points.
_LEGEND_HEADROOM = 1.4


def _world_axis(ax, order: list[str], ylabel: str) -> None:
    ax.set_xticks(
        np.arange(len(order)),
        labels=order,
        rotation=90 if len(order) > 8 else 0,
        fontsize=7 if len(order) > 20 else 8,
    )
    ax.set_xlim(-0.6, len(order) - 0.4)
    ax.set_xlabel("world")
    ax.set_ylabel(ylabel)
    ax.grid(axis="y", alpha=0.3)


def draw_cost_per_world(
    ax, runs: pd.DataFrame, column: str, worlds: list[str], ylabel: str, *, legend: bool = False
) -> pd.Series:
    """Every run's ``column`` as a point per world (gid ``"runs"``) and each world's mean (gid ``"means"``).

    ``worlds`` orders the worlds along x; ``legend`` adds one, above the points. Returns the means drawn
    (NaN for a world without the figure).
    """
    require_columns(runs, ("world",))
    values = cost_values(runs, column)
    names = runs["world"].astype(str).to_numpy()
    keep = np.isfinite(values)
    means = pd.Series(values[keep], index=names[keep]).groupby(level=0).mean().reindex(worlds)
    x = _positions(names, worlds)
    ax.plot(x[keep], values[keep], "o", ms=3, color="tab:blue", alpha=0.6, label="runs", gid="runs")
    ax.plot(np.arange(len(worlds)), means.to_numpy(), "_", ms=14, mew=2, color="tab:orange", label="mean", gid="means")
    _world_axis(ax, worlds, ylabel)
    _from_zero(ax, values, headroom=_LEGEND_HEADROOM if legend else 1.08)
    if legend:
        ax.legend(fontsize=7, loc="upper right")
    return means


def draw_update_times(ax, runs: pd.DataFrame, worlds: list[str]) -> pd.Series:
    """Each run's median time per SLAM update (points, gid ``"runs"``) and its 90th percentile (small
    crosses, gid ``"p90"``), per world, with the mean of the medians (gid ``"means"``). Needs ``world``,
    ``update_ms_median`` and ``update_ms_p90`` (ms). Returns the means of the medians."""
    means = draw_cost_per_world(ax, runs, "update_ms_median", worlds, "time per SLAM update (ms)")
    p90 = cost_values(runs, "update_ms_p90")
    names = runs["world"].astype(str).to_numpy()
    keep = np.isfinite(p90)
    x = _positions(names, worlds)
    ax.plot(x[keep], p90[keep], "x", ms=4, color="tab:gray", alpha=0.8, label="90th percentile", gid="p90")
    _from_zero(ax, cost_values(runs, "update_ms_median"), p90, headroom=_LEGEND_HEADROOM)
    ax.legend(fontsize=7, loc="upper right")
    return means
