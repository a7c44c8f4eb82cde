"""How well a world's runs mapped it, on average: :class:`WorldMapQuality`, from the catalog's run details.

Each figure is the mean, over the world's done runs that recorded it, of the run's own figure
(:class:`~slamtrials.metric.mapquality.MapQuality`, its definitions in
:data:`~slamtrials.metric.mapquality.DEFINITIONS`): occupied-cell precision and recall within 1 and 2
cells, free-space IoU (shares, 0..1) and ghost free area (m^2). Runs without a map, and runs stored by
earlier versions, recorded none: a world without any has no :class:`WorldMapQuality`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from slamtrials.campaign.detailmeans import csv_cells, figure_means
from slamtrials.metric.mapquality import MAP_QUALITY_FIGURES

__all__ = ["WorldMapQuality", "world_map_quality", "MAP_QUALITY_CSV_COLUMNS", "map_quality_csv_cells"]

#: The map-quality columns of summary.csv: the mean of each run figure (empty where no run recorded it).
MAP_QUALITY_CSV_COLUMNS = tuple(f"{name}_mean" for name in MAP_QUALITY_FIGURES)


@dataclass(frozen=True)
class WorldMapQuality:
    """Mean map quality per run of one world (None where no run recorded that figure).

    Attributes
    ----------
    runs:
        Done runs that recorded a map quality.
    occupied_precision_1, occupied_recall_1, occupied_precision_2, occupied_recall_2:
        Mean occupied-cell precision and recall within 1 and 2 cells (0..1).
    free_iou:
        Mean free-space intersection over union (0..1).
    ghost_free_m2:
        Mean area mapped free outside the reachable space (m^2).
    """

    runs: int
    occupied_precision_1: float | None
    occupied_recall_1: float | None
    occupied_precision_2: float | None
    occupied_recall_2: float | None
    free_iou: float | None
    ghost_free_m2: float | None

    def means(self) -> tuple[float | None, ...]:
        """The figures in the order of :data:`~slamtrials.metric.mapquality.MAP_QUALITY_FIGURES`."""
        return tuple(getattr(self, name) for name in MAP_QUALITY_FIGURES)


def world_map_quality(details: Iterable[Mapping[str, Any]]) -> WorldMapQuality | None:
    """The mean map quality over the runs whose ``details`` (the catalog's JSON of each done run) hold one;
    None when none does."""
    found = figure_means(details, MAP_QUALITY_FIGURES)
    return None if found is None else WorldMapQuality(runs=found[0], **found[1])


def map_quality_csv_cells(quality: WorldMapQuality | None) -> list[str]:
    """The :data:`MAP_QUALITY_CSV_COLUMNS` cells of a summary.csv row (empty where unknown)."""
    return csv_cells(None if quality is None else quality.means(), len(MAP_QUALITY_FIGURES))
