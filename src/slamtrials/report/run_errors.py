"""The report's Fig. 1: every world's run errors sorted from largest to smallest (all worlds on one figure,
as the paper prints it), then a gallery of one figure per world with its runs labelled and the mean's
confidence band."""

from __future__ import annotations

from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.tables import METRICS

__all__ = ["run_errors_section", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "fig-1"


def run_errors_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="fig-1"``): the figure of all worlds (``id="fig-1-all"``), then one figure per
    world in the order of Table I; a line saying there is nothing to draw when no run has finished."""
    data, done = view.data, view.done
    if done.empty:
        return h.section("Fig. 1: run errors per world", "<p>No finished runs.</p>", id=SECTION_ID)
    fig = figs.new(11, 3.8)
    for ax, metric in zip(fig.subplots(1, 2), METRICS):
        cf.draw_sorted_errors(ax, done, view.worlds, metric)
    overall = figs.save(
        fig,
        "fig1_all",
        "Every world's run errors sorted from largest to smallest (the paper's Fig. 1 "
        "as printed): left translational, right rotational.",
        id="fig-1-all",
    )
    gallery = []
    for i, world in enumerate(view.worlds):
        n = int((done["world"] == world).sum())
        fig = figs.new(min(4 + 0.18 * n, 14) * 2 / 1.6, 3.4)
        for ax, metric in zip(fig.subplots(1, 2), METRICS):
            cf.draw_world_errors(ax, done, world, metric, confidence=data.confidence, distribution=data.distribution)
        gallery.append(
            figs.save(
                fig,
                f"fig1_{i:03d}_{world}",
                f"{world}: its {n} runs' errors, largest first, labelled by run index; the mean and its "
                f"{h.fmt_percent(data.confidence)} confidence band.",
            )
        )
    return h.section(
        "Fig. 1: run errors per world, largest first",
        overall,
        '<div class="gallery">' + "\n".join(gallery) + "</div>",
        id=SECTION_ID,
        intro="The variability of one algorithm in one building: why a single run is not a measurement.",
    )
