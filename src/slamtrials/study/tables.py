"""The study's table of every cell: per cell and world, the runs, the mean errors with their intervals and
the mean cost of a run, read from each cell's campaign (:func:`slamtrials.report.load.load_campaign`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd

from slamtrials.report.load import CampaignData
from slamtrials.study.cells import Cell
from slamtrials.study.config import value_text

__all__ = ["cells_table", "CELL_COLUMNS", "finished_runs"]

#: Columns of :func:`cells_table` after ``cell`` and the axis keys (errors in m and rad, CPU in s, memory
#: in MiB, update times in ms; intervals at the cell's confidence; the mean coverage at the end, 0..1, and
#: the mean simulated time, s, and distance, m, to 90 % and 99 % coverage over the runs that reached it).
CELL_COLUMNS = (
    "world",
    "status",
    "runs",
    "capped",
    "eps_t_mean",
    "eps_t_ci_low",
    "eps_t_ci_high",
    "eps_r_mean",
    "eps_r_ci_low",
    "eps_r_ci_high",
    "confidence",
    "slam_cpu_s_mean",
    "slam_peak_mib_mean",
    "update_ms_median_mean",
    "run_cpu_s_mean",
    "run_peak_mib_mean",
    "coverage_final_mean",
    "time_to_90_s_mean",
    "distance_to_90_m_mean",
    "time_to_99_s_mean",
    "distance_to_99_m_mean",
)


def finished_runs(data: CampaignData) -> pd.DataFrame:
    """The done runs of a cell with finite errors."""
    done = data.done
    return done[done["eps_t"].notna() & done["eps_r"].notna()].reset_index(drop=True)


def cells_table(cells: Sequence[Cell], keys: Sequence[str], data: Mapping[str, CampaignData]) -> pd.DataFrame:
    """One row per (cell, world) of the cells that have a campaign folder, in cell then world order.

    Columns: ``cell``, ``combination`` (a named cell), each of ``keys`` (the cell's value as text, empty
    where it does not set it), then :data:`CELL_COLUMNS`.
    """
    rows = []
    for cell in cells:
        campaign = data.get(cell.name)
        if campaign is None:
            continue
        settings = dict(cell.settings)
        for _, world in campaign.worlds.iterrows():
            row = {"cell": cell.name, "combination": cell.combination}
            row.update({k: value_text(settings[k]) if k in settings else "" for k in keys})
            row.update({c: world["world"] if c == "world" else world.get(c) for c in CELL_COLUMNS if c != "runs"})
            row["runs"] = int(world["runs_done"])
            rows.append(row)
    columns = ["cell", "combination", *keys, *CELL_COLUMNS]
    return pd.DataFrame(rows, columns=columns)
