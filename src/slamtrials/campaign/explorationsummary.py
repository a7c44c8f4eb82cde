"""How fast a world's runs explored, on average: :class:`WorldExploration`, from the catalog's run details.

Each run's figures are its :class:`~slamtrials.trial.exploration.ExplorationMeasures`: the coverage at the
end (the share of the reachable free area the final SLAM map knows), and the simulated time (s) and the
true path's length (m) until the coverage first reached 90 % and 99 %. Per world: the mean final
coverage, how many runs reached each threshold, and the mean time and distance over the runs that
reached it. Runs stored by earlier versions recorded none: a world without any has no
:class:`WorldExploration`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from slamtrials.campaign.detailmeans import csv_cells, figure, mean_of
from slamtrials.trial.exploration import EXPLORATION_FIGURES, EXPLORATION_KEY, ExplorationMeasures

__all__ = [
    "WorldExploration",
    "world_exploration",
    "EXPLORATION_CSV_COLUMNS",
    "exploration_csv_cells",
    "ExplorationMeasures",
    "EXPLORATION_KEY",
    "EXPLORATION_FIGURES",
]

#: The exploration columns of summary.csv.
EXPLORATION_CSV_COLUMNS = (
    "exploration_runs",
    "coverage_final_mean",
    "reached_90",
    "time_to_90_s_mean",
    "distance_to_90_m_mean",
    "reached_99",
    "time_to_99_s_mean",
    "distance_to_99_m_mean",
)


@dataclass(frozen=True)
class WorldExploration:
    """Exploration of one world's done runs (None where no run reached a threshold).

    Attributes
    ----------
    runs:
        Done runs that recorded exploration measures.
    coverage_final:
        Mean coverage at the end of the runs (0..1).
    reached_90, reached_99:
        Runs whose coverage reached 90 % (99 %).
    time_to_90_s, distance_to_90_m, time_to_99_s, distance_to_99_m:
        Mean simulated time (s) and true path length (m) to 90 % (99 %) coverage, over the runs that
        reached it.
    """

    runs: int
    coverage_final: float
    reached_90: int
    time_to_90_s: float | None
    distance_to_90_m: float | None
    reached_99: int
    time_to_99_s: float | None
    distance_to_99_m: float | None

    def cells(self) -> tuple[float | int | None, ...]:
        """The figures in the order of :data:`EXPLORATION_CSV_COLUMNS`."""
        return (
            self.runs,
            self.coverage_final,
            self.reached_90,
            self.time_to_90_s,
            self.distance_to_90_m,
            self.reached_99,
            self.time_to_99_s,
            self.distance_to_99_m,
        )


def world_exploration(details: Iterable[Mapping[str, Any]]) -> WorldExploration | None:
    """The exploration of the runs whose ``details`` (the catalog's JSON of each done run) hold measures
    (a ``final_coverage``); None when none does."""
    rows = [d for d in details if figure(d.get("final_coverage")) is not None]
    if not rows:
        return None
    figures = {
        name: [figure(d.get(name)) for d in rows]
        for name in ("time_to_90_s", "distance_to_90_m", "time_to_99_s", "distance_to_99_m")
    }
    return WorldExploration(
        runs=len(rows),
        coverage_final=math.fsum(float(d["final_coverage"]) for d in rows) / len(rows),
        reached_90=sum(v is not None for v in figures["time_to_90_s"]),
        time_to_90_s=mean_of(figures["time_to_90_s"]),
        distance_to_90_m=mean_of(figures["distance_to_90_m"]),
        reached_99=sum(v is not None for v in figures["time_to_99_s"]),
        time_to_99_s=mean_of(figures["time_to_99_s"]),
        distance_to_99_m=mean_of(figures["distance_to_99_m"]),
    )


def exploration_csv_cells(exploration: WorldExploration | None) -> list[str]:
    """The :data:`EXPLORATION_CSV_COLUMNS` cells of a summary.csv row (empty where unknown)."""
    return csv_cells(None if exploration is None else exploration.cells(), len(EXPLORATION_CSV_COLUMNS))
