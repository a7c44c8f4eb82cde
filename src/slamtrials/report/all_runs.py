"""The report's Fig. 5: every run of every world on one figure, a box per world, outliers (Tukey's fences,
the outlier column of Table I) marked."""

from __future__ import annotations

from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.tables import METRICS, SYMBOLS

__all__ = ["all_runs_section", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "fig-5"


def all_runs_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="fig-5"``): the figure, ``eps_t`` above ``eps_r``, worlds in the order of
    Table I, with a caption that counts the outliers."""
    done = view.done
    if done.empty:
        return h.section("Fig. 5: all runs of all worlds", "<p>No finished runs.</p>", id=SECTION_ID)
    fig = figs.new(min(max(7.0, 0.45 * len(view.worlds) + 3), 30), 7.5)
    for ax, metric in zip(fig.subplots(2, 1), METRICS):
        cf.draw_all_runs(ax, done, metric, order=view.worlds)
    count_t, count_r = int(done["outlier_t"].sum()), int(done["outlier_r"].sum())
    caption = (
        f"The paper's Fig. 5: every run of every world (points), a box per world (quartiles, whiskers at 1.5 IQR), "
        f"the world means (orange), and outliers beyond Tukey's fences (the outlier column of Table I) as red "
        f"crosses: {count_t} in {SYMBOLS['eps_t']} (top), {count_r} in {SYMBOLS['eps_r']} (bottom). Worlds in the "
        "order of Table I."
    )
    return h.section(
        "Fig. 5: all runs of all worlds, outliers marked", figs.save(fig, "fig5_all_runs", caption), id=SECTION_ID
    )
