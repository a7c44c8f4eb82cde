"""The report's section on how the runs ended: termination reasons per world, the explored fraction of
every run, and a table of both with the runs' mean simulated and wall-clock time."""

from __future__ import annotations

from collections import Counter

import numpy as np

from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.figure_writer import FigureWriter

__all__ = ["termination_section", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "termination"

_TITLE = "How the runs ended: termination reasons and explored fraction"


def termination_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="termination"``): the figure (reasons left, explored fraction right when any
    run recorded one) and ``<table id="termination-table">``, worlds in the order of Table I."""
    done, worlds = view.done, view.worlds
    if done.empty:
        return h.section(_TITLE, "<p>No finished runs.</p>", id=SECTION_ID)
    mapped = done[np.isfinite(done["mapped"])]
    fig = figs.new(min(max(10.0, 0.6 * done["world"].nunique() + 4), 30), 4.0)
    axes = fig.subplots(1, 2 if len(mapped) else 1, squeeze=False)[0]
    cf.draw_termination(axes[0], done, worlds)
    if len(mapped):
        cf.draw_explored(axes[1], mapped, worlds)
    picture = figs.save(
        fig,
        "termination",
        "Left: why the runs ended, per world (run counts). Right: the fraction of each "
        "world's free space the robot's footprint can reach that the final map knows (free or occupied), per run, "
        "and its mean. Worlds in the order of Table I.",
    )
    rows = []
    for world in worlds:
        mine = done[done["world"] == world]
        reasons = Counter(mine["termination"].fillna("unknown"))
        rows.append(
            [
                world,
                len(mine),
                ", ".join(f"{k} {v}" for k, v in sorted(reasons.items())),
                h.number_cell(mine["mapped"].mean(), 3),
                h.number_cell(mine["mapped"].min(), 3),
                h.seconds_cell(mine["duration_s"].mean()),
                h.seconds_cell(mine["wall_s"].mean()),
            ]
        )
    table = h.table(
        ["world", "runs", "ended by", "explored (mean)", "explored (min)", "simulated s (mean)", "wall s (mean)"],
        rows,
        id="termination-table",
    )
    return h.section(_TITLE, picture, table, id=SECTION_ID)
