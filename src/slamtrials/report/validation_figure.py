"""The validation figure (``slamtrials validate``): real errors next to the simulated replicas', drawn on a given Axes."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["ErrorBars", "draw_real_vs_simulated"]


@dataclass(frozen=True)
class ErrorBars:
    """One group of bars: what is scored (e.g. ``gmapping`` or ``odometry``) and its errors of one kind.

    Attributes
    ----------
    label:
        The group's name.
    real:
        The real log's error.
    mean, std:
        Mean and sample standard deviation over the simulated replicas (std NaN: no error bar).
    values:
        Every replica's error (drawn as dots).
    """

    label: str
    real: float
    mean: float
    std: float
    values: tuple[float, ...] = ()


def draw_real_vs_simulated(ax, groups: Sequence[ErrorBars], *, unit: str, title: str = "") -> None:
    """Bars of the real error and of the simulated mean (with +-1 std and each replica as a dot), per group.

    The y axis is logarithmic when every value is positive (odometry errors are often tens of times the
    SLAM errors).

    Parameters
    ----------
    ax:
        A matplotlib Axes.
    groups:
        The groups, left to right.
    unit:
        The errors' unit (for the y label).
    title:
        Axes title.
    """
    x = np.arange(len(groups), dtype=np.float64)
    width = 0.36
    real = np.array([g.real for g in groups], dtype=np.float64)
    mean = np.array([g.mean for g in groups], dtype=np.float64)
    std = np.array([g.std for g in groups], dtype=np.float64)
    ax.bar(x - width / 2, real, width, color="tab:gray", label="real log")
    has_std = np.isfinite(std)
    ax.bar(
        x + width / 2,
        mean,
        width,
        color="tab:blue",
        yerr=np.where(has_std, std, 0.0),
        capsize=4,
        label="simulated replicas (mean +- std)",
    )
    for k, group in enumerate(groups):
        if group.values:
            ax.plot(
                np.full(len(group.values), x[k] + width / 2),
                group.values,
                "o",
                color="black",
                markersize=3,
                label="replicas" if k == 0 else None,
            )
    every = np.concatenate([real, mean, *[np.asarray(g.values, dtype=np.float64) for g in groups]])
    every = every[np.isfinite(every)]
    if len(every) and every.min() > 0:  # room above the bars for the legend
        ax.set_yscale("log")
        ax.set_ylim(every.min() / 2.0, every.max() * 12.0)
    elif len(every):
        ax.set_ylim(0.0, every.max() * 1.6)
    ax.set_xticks(x)
    ax.set_xticklabels([g.label for g in groups])
    ax.set_ylabel(f"mean error ({unit})")
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, axis="y", which="both", alpha=0.3)
