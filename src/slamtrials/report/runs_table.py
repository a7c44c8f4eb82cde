"""The report's table of every run of the campaign (done, failed and unfinished): seed, status, errors,
outlier marks, how it ended, times, cost and error message, collapsed under a one-line summary."""

from __future__ import annotations

import pandas as pd

from slamtrials.report import html as h
from slamtrials.report.load import CampaignData
from slamtrials.report.tables import SYMBOLS

__all__ = ["runs_section", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "runs"

_HEADER = [
    "world",
    "run",
    "seed",
    "status",
    "\u03b5t (m)",
    "\u03b5r (rad)",
    "outlier in",
    "ended by",
    "explored",
    "sim s",
    "wall s",
    "SLAM CPU s",
    "ms per update",
    "SLAM MiB",
    "error",
]


def runs_section(data: CampaignData) -> str:
    """The section (HTML, ``id="runs"``): ``<table id="runs-table">``, one row per run of ``data.runs`` in
    the catalog's order (failed runs red, outliers yellow), in a ``<details>`` block."""
    rows, classes = [], []
    for _, r in data.runs.iterrows():
        flag = ", ".join(SYMBOLS[m] for m, c in (("eps_t", r["outlier_t"]), ("eps_r", r["outlier_r"])) if c)
        rows.append(_row(r, flag))
        classes.append("bad" if r["status"] == "failed" else ("warn" if flag else None))
    table = h.table(
        _HEADER,
        rows,
        id="runs-table",
        row_classes=classes,
        caption="outlier in: the errors in which the run lies beyond its world's Tukey fences (see the outlier "
        "column of Table I); sim s: simulated duration; wall s: the run's wall-clock time on its worker; SLAM CPU s, "
        "ms per update (median) and SLAM MiB: what the run cost (see the section on cost).",
    )
    summary = f"{len(data.runs)} runs with their seeds, errors and outlier marks"
    return h.section("Every run", h.details(summary, table), id=SECTION_ID)


def _row(run: pd.Series, flag: str) -> list:
    """The cells of one run; ``flag`` names the errors in which it is an outlier."""
    return [
        run["world"],
        h.Cell(str(run["run"]), numeric=True),
        h.Cell(str(run["seed"]), numeric=True),
        run["status"],
        h.number_cell(run["eps_t"], 4),
        h.number_cell(run["eps_r"], 4),
        flag,
        run["termination"] if isinstance(run["termination"], str) else "",
        h.number_cell(run["mapped"], 3),
        h.seconds_cell(run["duration_s"]),
        h.seconds_cell(run["wall_s"]),
        h.seconds_cell(run.get("slam_cpu_s")),
        h.seconds_cell(run.get("update_ms_median")),
        h.seconds_cell(run.get("slam_peak_mib")),
        run["error"] if isinstance(run["error"], str) else "",
    ]
