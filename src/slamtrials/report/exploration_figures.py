"""How fast the runs of a world explored, drawn on a given matplotlib Axes: every run's coverage curve.

A curve is :class:`~slamtrials.trial.exploration.ExplorationMeasures`' ``curve_t`` (simulated s since the
start) and ``curve_coverage`` (the share of the reachable free area the final map knows and the map of
that time already knew), drawn as a percentage. Artists carry a ``gid``: ``"run:<index>"`` per curve,
``"reached:90"`` and ``"reached:99"`` for the points where runs first reached a threshold, and
``"threshold:90"``, ``"threshold:99"`` for the threshold lines.
"""

from __future__ import annotations

from collections.abc import Mapping

from slamtrials.campaign.explorationsummary import ExplorationMeasures

__all__ = ["draw_coverage_curves"]

#: The thresholds drawn, with their line styles.
_THRESHOLDS = ((0.90, "--"), (0.99, ":"))


def draw_coverage_curves(ax, runs: Mapping[int, ExplorationMeasures], *, title: str | None = None) -> None:
    """Every run's coverage curve (thin lines, run index -> measures in ``runs``), time on x, the 90 % and
    99 % thresholds as grey lines, and where each run first reached them (small dots); a legend of the
    thresholds in the lower right, below the saturated curves. Runs with an empty curve are skipped."""
    right = 0.0
    for index, found in sorted(runs.items()):
        if not found.curve_t:
            continue
        t = list(found.curve_t)
        right = max(right, t[-1])
        ax.plot(t, [100.0 * c for c in found.curve_coverage], lw=0.8, alpha=0.7, color="tab:blue", gid=f"run:{index}")
    for threshold, style in _THRESHOLDS:
        percent = round(100 * threshold)
        ax.axhline(100.0 * threshold, ls=style, lw=0.8, color="0.4", label=f"{percent} %", gid=f"threshold:{percent}")
    for threshold, _ in _THRESHOLDS:
        percent = round(100 * threshold)
        reached = [(f.time_to(threshold), 100.0 * threshold) for f in runs.values() if f.time_to(threshold) is not None]
        if reached:
            xs, ys = zip(*reached)
            label = "first reached" if threshold == _THRESHOLDS[0][0] else None
            ax.plot(xs, ys, "o", ms=3, color="tab:orange", alpha=0.8, label=label, gid=f"reached:{percent}")
    ax.set_xlim(0.0, right * 1.02 if right > 0 else 1.0)
    ax.set_ylim(0.0, 102.0)
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel("reachable area mapped (%)")
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9)
    ax.legend(title="coverage", fontsize=7, title_fontsize=7, loc="lower right")
