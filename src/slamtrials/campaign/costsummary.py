"""What a world's runs cost, on average: :class:`WorldCost`, from the catalog's run details.

Each figure is the mean, over the world's done runs that recorded it, of the run's own figure
(:class:`~slamtrials.cost.RunCost`): SLAM and whole-run CPU time (s), SLAM and whole-run peak memory (MiB),
and the median and 90th percentile of the time per SLAM update (ms). Costs are measurements of the machine
(another run of the same campaign gives other figures), so they are reported, never compared as results.
Runs stored by earlier versions recorded none: a world without any has no :class:`WorldCost`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from slamtrials.campaign.detailmeans import csv_cells, figure_means
from slamtrials.cost import COST_FIGURES

__all__ = ["WorldCost", "world_cost", "COST_CSV_COLUMNS", "cost_csv_cells"]

#: The cost columns of summary.csv: the mean of each run figure (empty where no run recorded it).
COST_CSV_COLUMNS = tuple(f"{name}_mean" for name in COST_FIGURES)


@dataclass(frozen=True)
class WorldCost:
    """Mean cost per run of one world (None where no run recorded that figure).

    Attributes
    ----------
    runs:
        Done runs that recorded a cost.
    slam_cpu_s, run_cpu_s:
        Mean CPU time (s) of the SLAM algorithm and of the whole run.
    slam_peak_mib, run_peak_mib:
        Mean peak memory (MiB) of the SLAM algorithm and of the whole run.
    update_ms_median, update_ms_p90:
        Mean over the runs of each run's median and 90th percentile time per SLAM update (ms).
    """

    runs: int
    slam_cpu_s: float | None
    slam_peak_mib: float | None
    run_cpu_s: float | None
    run_peak_mib: float | None
    update_ms_median: float | None
    update_ms_p90: float | None

    def means(self) -> tuple[float | None, ...]:
        """The figures in the order of :data:`~slamtrials.cost.COST_FIGURES`."""
        return tuple(getattr(self, name) for name in COST_FIGURES)


def world_cost(details: Iterable[Mapping[str, Any]]) -> WorldCost | None:
    """The mean cost over the runs whose ``details`` (the catalog's JSON of each done run) hold one; None
    when none does."""
    found = figure_means(details, COST_FIGURES)
    return None if found is None else WorldCost(runs=found[0], **found[1])


def cost_csv_cells(cost: WorldCost | None) -> list[str]:
    """The :data:`COST_CSV_COLUMNS` cells of a summary.csv row (empty where unknown)."""
    return csv_cells(None if cost is None else cost.means(), len(COST_FIGURES))
