"""The report's section on map quality: per world, the mean of each run's map figures, and what each one is.

Reads the runs table of :func:`slamtrials.report.load.load_campaign` (one row per finished run, the
catalog's ``details`` as columns: ``occupied_precision_1``, ..., ``ghost_free_m2``,
:class:`slamtrials.metric.mapquality.MapQuality`). Runs without a map quality (a run without a map, a replay
whose world did not load, runs of earlier versions) are left out of the means and counted apart.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from slamtrials.metric.mapquality import DEFINITIONS, GHOST_TOLERANCE_CELLS, MAP_QUALITY_FIGURES, TOLERANCES_CELLS
from slamtrials.report import html as h
from slamtrials.report.tables import column_values, finite_mean

__all__ = ["map_quality_section", "map_quality_values", "SECTION_ID", "TITLE"]

#: The section's anchor and title.
SECTION_ID = "map-quality"
TITLE = "Map quality: the final maps against the floor plans"

#: Column headings of the per-world table, by figure.
_HEADINGS = {
    "occupied_precision_1": "wall precision (1 cell)",
    "occupied_recall_1": "wall recall (1 cell)",
    "occupied_precision_2": "wall precision (2 cells)",
    "occupied_recall_2": "wall recall (2 cells)",
    "free_iou": "free IoU",
    "ghost_free_m2": "ghost m\u00b2",
}


def map_quality_values(runs: pd.DataFrame, name: str) -> np.ndarray:
    """float64 ``[R]``: figure ``name`` of every run (NaN where missing; an absent column is all NaN)."""
    return column_values(runs, name)


def _explanation() -> str:
    """How the maps are placed and compared, and each figure's definition, in a collapsed block."""
    tolerances = " and ".join(str(k) for k in TOLERANCES_CELLS)
    intro = (
        "Each run's final SLAM map is placed on the floor plan by the least-squares rigid fit of its estimated "
        "trajectory onto the true one (the map is drawn in the estimate's frame), and every cell is compared at "
        "its centre with the nearest cell of the other grid; a cell is the SLAM map's (its resolution), unknown "
        "cells count as neither free nor occupied. The reachable space is the floor plan's free space connected to "
        "the start; its walls are the wall cells that share a side with it. Tolerances: "
        f"{tolerances} cells for walls, {GHOST_TOLERANCE_CELLS} for ghost area. A map that is bent (drift the "
        "rigid fit cannot take out) loses precision and recall as one that is wrong does."
    )
    items = "".join(
        f"<li><b>{h.esc(_HEADINGS[name])}</b> (<code>{h.esc(name)}</code>): {h.esc(DEFINITIONS[name])}</li>"
        for name in MAP_QUALITY_FIGURES
    )
    return h.details(
        "How the maps are scored, and what each column is",
        h.explanation(intro, id="map-quality-note") + f'<ul id="map-quality-definitions">{items}</ul>',
        css_class="explain",
    )


def map_quality_section(done: pd.DataFrame, worlds: list[str]) -> str:
    """The section's HTML: one row per world of ``worlds`` (in that order) with the number of runs scored and
    the mean of each figure over them, then how the maps are scored and the definitions, collapsed; ``done``
    holds the finished runs."""
    scored = np.zeros(len(done), dtype=bool)
    for name in MAP_QUALITY_FIGURES:
        scored |= np.isfinite(map_quality_values(done, name))
    if not scored.any():
        return h.section(TITLE, "<p>No finished run recorded its map quality.</p>", _explanation(), id=SECTION_ID)
    rows = []
    for world in worlds:
        mine = done[(done["world"] == world).to_numpy() & scored]
        cells = [
            h.Cell(
                h.fmt_number(finite_mean(map_quality_values(mine, name)), 2 if name == "ghost_free_m2" else 3),
                numeric=True,
            )
            for name in MAP_QUALITY_FIGURES
        ]
        rows.append([world, h.Cell(str(len(mine)), numeric=True), *cells])
    unscored = int((~scored).sum())
    table = h.table(
        ["world", "runs scored", *(_HEADINGS[name] for name in MAP_QUALITY_FIGURES)],
        rows,
        id="map-quality-table",
        caption="Means over the world's runs that recorded a map quality; shares from 0 to 1 (higher is better), "
        "ghost area in m\u00b2 (lower is better)."
        + (f" {unscored} finished run(s) recorded none (no map, or a world that did not load)." if unscored else ""),
    )
    return h.section(TITLE, table, _explanation(), id=SECTION_ID)
