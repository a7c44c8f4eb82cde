"""The report's Fig. 6: pairs of worlds where one run of each would rank them opposite to their mean errors
(:func:`slamtrials.report.compare.world_pair_traps`), the most misleading pair drawn, and a table of the
pairs (``id="trap-table"``)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.compare import world_pair_traps
from slamtrials.report.figure_writer import FigureWriter

__all__ = ["world_traps_section", "SECTION_ID", "MAX_PAIRS"]

#: The section's anchor.
SECTION_ID = "fig-6"
#: Rows of the table at the most.
MAX_PAIRS = 15

_TITLE = "Fig. 6: where single runs mislead"
_INTRO = "The paper's Fig. 6: for two worlds, one run of each can rank them opposite to their mean errors."
_HEADER = [
    "lower-mean world",
    "mean (m)",
    "higher-mean world",
    "mean (m)",
    "Welch p",
    "means differ (5 %)",
    "misleading run of the first",
    "misleading run of the second",
    "run pairs reversed",
]


def world_traps_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="fig-6"``) on the translational error: the runs of the most misleading pair of
    worlds with their means, a sentence on it, and the table of the pairs that single runs reverse (those whose
    means differ significantly first, then by how much they are reversed)."""
    done = view.done
    if done["world"].nunique() < 2:
        return h.section(_TITLE, "<p>Needs finished runs in at least two worlds.</p>", id=SECTION_ID)
    traps = world_pair_traps(done, "eps_t")
    reversed_ = traps[traps["reversed_by"] > 0].sort_values(
        ["means_differ", "reversed_by"], ascending=False, kind="stable"
    )
    if reversed_.empty:
        return h.section(
            _TITLE,
            "<p>No pair of worlds has a single-run comparison that contradicts the means.</p>",
            id=SECTION_ID,
            intro=_INTRO,
        )
    top = reversed_.iloc[0]
    table = h.table(
        _HEADER,
        [_row(r) for _, r in reversed_.head(MAX_PAIRS).iterrows()],
        id="trap-table",
        caption="Pairs of worlds where this happens (translational error): first those whose means differ "
        "significantly (Welch, 5 %), then by how much the single runs reverse them.",
    )
    return h.section(
        _TITLE, _picture(figs, done, top), f"<p>{h.esc(_sentence(top))}</p>", table, id=SECTION_ID, intro=_INTRO
    )


def _row(pair: pd.Series) -> list:
    """A row of the table: one pair of worlds of :func:`~slamtrials.report.compare.world_pair_traps`."""
    return [
        pair["world_low"],
        h.number_cell(pair["mean_low"]),
        pair["world_high"],
        h.number_cell(pair["mean_high"]),
        h.number_cell(pair["p"], 4),
        "yes" if pair["means_differ"] else "no",
        f"#{pair['run_low']}: {pair['value_low']:.3f} m",
        f"#{pair['run_high']}: {pair['value_high']:.3f} m",
        h.Cell(f"{pair['reversed_fraction']:.0%}", numeric=True),
    ]


def _sentence(top: pd.Series) -> str:
    """What the most misleading pair of worlds shows, in words."""
    return (
        f"{top['world_low']} has the lower mean error ({top['mean_low']:.3f} m against {top['mean_high']:.3f} m), "
        f"but its run #{top['run_low']} ({top['value_low']:.3f} m) is worse than run #{top['run_high']} of "
        f"{top['world_high']} ({top['value_high']:.3f} m): comparing these two single runs gives the opposite verdict; "
        f"{top['reversed_fraction']:.0%} of all pairs of single runs do. The difference of the means is "
        f"{'significant' if top['means_differ'] else 'not significant'} (Welch p = {top['p']:.3g})."
    )


def _picture(figs: FigureWriter, done: pd.DataFrame, top: pd.Series) -> str:
    """The figure of the most misleading pair ``top``: both worlds' runs, their means, the pair ringed."""
    low = done.loc[done["world"] == top["world_low"], ["run", "eps_t"]]
    high = done.loc[done["world"] == top["world_high"], ["run", "eps_t"]]
    fig = figs.new(5.0, 3.6)
    cf.draw_trap_pair(
        fig.subplots(),
        low["eps_t"].to_numpy(),
        high["eps_t"].to_numpy(),
        (top["world_low"], top["world_high"]),
        int(np.flatnonzero(low["run"].to_numpy() == top["run_low"])[0]),
        int(np.flatnonzero(high["run"].to_numpy() == top["run_high"])[0]),
    )
    return figs.save(
        fig,
        "fig6_trap",
        f"The runs of {top['world_low']} and {top['world_high']} with their means; "
        "ringed and joined: the single-run pair that contradicts the means the most.",
    )
