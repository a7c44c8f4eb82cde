"""The report's section on how fast the runs explored (Explore-Bench's measures): :func:`exploration_section`.

Per world: every finished run's coverage curve on one Axes (:func:`~slamtrials.report.exploration_figures.
draw_coverage_curves`), and a table of how many runs reached 90 % and 99 % coverage, their mean time and
distance to it, the mean final coverage and how the runs ended. The measures are read from each run's
run.json (``exploration``, :class:`~slamtrials.trial.exploration.ExplorationMeasures`); runs stored by an
earlier version have none and are counted in a note.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from typing import Any

import pandas as pd

from slamtrials.campaign.detailmeans import mean_of
from slamtrials.campaign.explorationsummary import ExplorationMeasures
from slamtrials.io.layout import RunFolder
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.exploration_figures import draw_coverage_curves
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.load import CampaignData

__all__ = ["exploration_section", "read_exploration", "EXPLORATION_TEXT", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "exploration"

#: What the section's measures are, as the page explains them.
EXPLORATION_TEXT = (
    "Coverage at a time t: the share of the free area the robot's footprint can reach from the start that the "
    "final SLAM map knows (free or occupied) and that the SLAM map of time t already knew, sampled whenever "
    "SLAM published a new map (at most once a simulated second, or 4 s per million map cells); it ends at the explored fraction above. Time "
    "and distance to 90 % (99 %): the simulated seconds and the length of the true path from the start to "
    "the first sample at or above that coverage, averaged over the runs that reached it (as Explore-Bench "
    "reports exploration). In a replay they are the source runs' (the robot explored with the first "
    "algorithm's maps)."
)


def read_exploration(data: CampaignData, done: pd.DataFrame) -> dict[str, dict[int, ExplorationMeasures]]:
    """``{world: {run index: measures}}`` of the runs in ``done`` (columns ``world``, ``run``) whose run.json
    holds exploration measures; a run.json that is missing or unreadable counts as holding none."""
    found: dict[str, dict[int, ExplorationMeasures]] = {}
    for world, run in zip(done["world"].astype(str), done["run"].astype(int)):
        try:
            doc = json.loads(RunFolder(data.run_folder(world, run)).run_json.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        measures = ExplorationMeasures.of(doc) if isinstance(doc, dict) else None
        if measures is not None:
            found.setdefault(world, {})[run] = measures
    return found


def _row(world: str, runs: dict[int, ExplorationMeasures]) -> list[Any]:
    """The table's row of ``world``: runs, and per threshold how many reached it and their mean time (s) and
    distance (m) to it; mean final coverage; how the runs ended."""
    measures = list(runs.values())
    cells: list[Any] = [world, h.Cell(str(len(measures)), numeric=True)]
    for threshold in (0.90, 0.99):
        reached = [m for m in measures if m.reached(threshold)]
        cells += [
            h.Cell(f"{len(reached)} of {len(measures)}", numeric=True),
            h.Cell(h.fmt_seconds(mean_of(m.time_to(threshold) for m in reached)), numeric=True),
            h.Cell(h.fmt_number(mean_of(m.distance_to(threshold) for m in reached), 1), numeric=True),
        ]
    final = mean_of(m.final_coverage for m in measures if math.isfinite(m.final_coverage))
    reasons = Counter(m.termination_reason for m in measures)
    cells += [
        h.Cell("-" if final is None else f"{100 * final:.1f} %", numeric=True),
        ", ".join(f"{k} {v}" for k, v in sorted(reasons.items())),
    ]
    return cells


def exploration_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="exploration"``): the coverage curves of every world (in the order of Table I)
    that has measures, the table of the measures (``id="exploration-table"``), a note counting the runs
    without them, then :data:`EXPLORATION_TEXT` collapsed (``id="exploration-note"``)."""
    title = "How fast the runs explored: coverage over time"
    explain = h.details(
        "How coverage, time and distance are measured",
        h.explanation(EXPLORATION_TEXT, id="exploration-note"),
        css_class="explain",
    )
    done = view.done
    found = read_exploration(view.data, done) if len(done) else {}
    shown = [w for w in view.worlds if found.get(w)]
    if not shown:
        return h.section(title, "<p>No finished run recorded exploration measures.</p>", explain, id=SECTION_ID)
    columns = min(3, len(shown))
    rows = math.ceil(len(shown) / columns)
    fig = figs.new(4.2 * columns, 3.2 * rows)
    axes = fig.subplots(rows, columns, squeeze=False)
    for i, world in enumerate(shown):
        ax = axes[i // columns][i % columns]
        draw_coverage_curves(ax, found[world], title=f"{world} ({len(found[world])} runs)")
    for j in range(len(shown), rows * columns):
        axes[j // columns][j % columns].set_visible(False)
    picture = figs.save(
        fig,
        "exploration",
        "Coverage over simulated time, every run a thin line, per world in the order of Table I: the share of the "
        "reachable free area the SLAM map had mapped. Dashed and dotted: 90 % and 99 %; dots: where each run first "
        "reached them.",
        id="exploration-figure",
    )
    table = h.table(
        [
            "world",
            "runs",
            "reached 90 %",
            "s to 90 %",
            "m to 90 %",
            "reached 99 %",
            "s to 99 %",
            "m to 99 %",
            "final coverage",
            "ended by",
        ],
        [_row(world, found[world]) for world in shown],
        id="exploration-table",
        caption="Time (simulated s) and distance (true path, m) to 90 % and 99 % coverage: means over the runs that "
        "reached it; final coverage: mean over the runs.",
    )
    missing = int(len(done)) - sum(len(runs) for runs in found.values())
    note = (
        h.notes([f"{missing} finished run(s) recorded no exploration measures (stored by an earlier version)."])
        if missing
        else ""
    )
    return h.section(title, picture, table, note, explain, id=SECTION_ID)
