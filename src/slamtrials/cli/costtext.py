"""What a run, or a world's runs, cost, as the one line the commands print (:class:`slamtrials.cost.RunCost`)."""

from __future__ import annotations

from collections.abc import Iterable

from slamtrials.cost import CHILD_PROCESS, RunCost

__all__ = ["run_cost_text", "world_cost_line"]


def _round(value: float | None, unit: str) -> str:
    """``6.4 s``, ``25 ms``, ``52 MiB``: one decimal below 10, whole numbers above; ``-`` when unknown."""
    if value is None:
        return "-"
    return f"{value:.1f} {unit}" if abs(value) < 9.95 else f"{value:.0f} {unit}"


def _update_text(median: float | None, p90: float | None) -> str | None:
    if median is None:
        return None
    return f"{_round(median, 'ms')} per update (p90 {_round(p90, 'ms')})"


def run_cost_text(cost: RunCost | None) -> str:
    """``cost: SLAM 6.4 s CPU, 52 MiB, 25 ms per update (p90 41 ms); whole run 8.6 s CPU, 280 MiB peak``, and
    ``; 48 s CPU compiling kernels, left out`` after it when the run compiled numba kernels."""
    if cost is None:
        return "cost: not measured"
    who = "the program's process" if cost.slam_process == CHILD_PROCESS else "SLAM"
    parts = [f"{_round(cost.slam_cpu_s, 's')} CPU", _round(cost.slam_peak_mib, "MiB")]
    update = _update_text(cost.update_ms_median, cost.update_ms_p90)
    if update:
        parts.append(update)
    line = (
        f"cost: {who} {', '.join(parts)}; whole run {_round(cost.run_cpu_s, 's')} CPU, "
        f"{_round(cost.run_peak_mib, 'MiB')} peak"
    )
    if cost.compile_cpu_s:
        line += f"; {_round(cost.compile_cpu_s, 's')} CPU compiling kernels, left out"
    return line


def world_cost_line(rows: Iterable) -> str | None:
    """One line: per world (:class:`~slamtrials.campaign.WorldSummary` rows), the mean SLAM CPU time,
    time per update and SLAM memory per run; None when no run recorded its cost."""
    parts = []
    for row in rows:
        cost = row.cost
        if cost is None:
            continue
        update = _update_text(cost.update_ms_median, cost.update_ms_p90)
        parts.append(
            f"{row.world} {_round(cost.slam_cpu_s, 's')} CPU"
            + (f", {update}" if update else "")
            + f", {_round(cost.slam_peak_mib, 'MiB')}"
        )
    if not parts:
        return None
    return "SLAM cost per run (mean): " + "; ".join(parts)
