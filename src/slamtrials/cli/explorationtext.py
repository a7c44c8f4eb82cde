"""How fast a run explored, as the one line ``slamtrials trial`` prints
(:class:`slamtrials.trial.exploration.ExplorationMeasures`)."""

from __future__ import annotations

from slamtrials.trial.exploration import THRESHOLDS, ExplorationMeasures

__all__ = ["exploration_text"]


def exploration_text(found: ExplorationMeasures | None) -> str:
    """``exploration: 90 % after 140 s and 51 m, 99 % after 191 s and 73 m; 100.0 % mapped at the end``
    (``never`` for a threshold not reached)."""
    if found is None:
        return "exploration: not recorded"
    parts = []
    for threshold in THRESHOLDS:
        time, distance = found.time_to(threshold), found.distance_to(threshold)
        reached = "never" if time is None or distance is None else f"after {time:.0f} s and {distance:.0f} m"
        parts.append(f"{round(100 * threshold)} % {reached}")
    return f"exploration: {parts[0]}, {parts[1]}; {100 * found.final_coverage:.1f} % mapped at the end"
