"""Figures of a repeated experiment on one dataset (``slamtrials slam --runs``), drawn on a given Axes."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["draw_repeated_errors"]


def draw_repeated_errors(ax, eps_t: ArrayLike, threshold: float, *, factor: float = 5.0, title: str = "") -> None:
    """The paper's Fig. 1 for a dataset: every run's mean translational error (m), sorted, on a log scale,
    with the divergence threshold as a dashed line and the diverged runs in red.

    Parameters
    ----------
    ax:
        A matplotlib Axes.
    eps_t:
        ``[R]`` per-run mean translational errors (m).
    threshold:
        Errors above this (m) count as diverged: ``factor`` times the median.
    title:
        Axes title.
    """
    values = np.sort(np.asarray(eps_t, dtype=np.float64).reshape(-1), kind="stable")
    rank = np.arange(1, len(values) + 1)
    above = values > threshold
    ax.plot(rank[~above], values[~above], "o", color="tab:blue", label="runs")
    if above.any():
        ax.plot(
            rank[above], values[above], "o", color="tab:red", label=f"diverged ({int(above.sum())} of {len(values)})"
        )
    ax.axhline(
        threshold, color="tab:red", linestyle="--", linewidth=1, label=f"{factor:g} x median = {threshold:.3g} m"
    )
    if len(values) and values.min() > 0:
        ax.set_yscale("log")
    ax.set_xlabel("run, sorted by error")
    ax.set_ylabel("mean translational error (m)")
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)
