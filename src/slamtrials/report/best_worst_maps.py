"""The report's Fig. 4: per world, the final SLAM maps of the runs with the smallest and the largest ``eps_t``,
the estimated trajectory drawn on each (map frame) and the true one fitted onto it
(:func:`slamtrials.report.alignment.align_truth`)."""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from slamtrials.errors import SlamtrialsError
from slamtrials.record import RunRecord
from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.alignment import TruthAlignment
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.figure_writer import FigureWriter, safe_name
from slamtrials.report.tables import SYMBOLS

__all__ = ["best_worst_maps_section", "SECTION_ID", "PAGE_WIDTH_IN"]

log = logging.getLogger(__name__)

#: The section's anchor.
SECTION_ID = "fig-4"
#: Width (inches, at 100 dpi) of a figure shown at the page's full width (its max-width is 1250 px).
PAGE_WIDTH_IN = 12.0

_TITLE = "Fig. 4: best and worst map of every world"


def best_worst_maps_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="fig-4"``): one figure per world in the order of Table I
    (``id="fig-4-<world>"``), the best run left and the worst right (one panel when they are the same run);
    a note for each world whose run folders could not be read."""
    done = view.done
    if done.empty:
        return h.section(_TITLE, "<p>No finished runs.</p>", id=SECTION_ID)
    pictures, problems = [], []
    for i, world in enumerate(view.worlds):
        try:
            pictures.append(_world_figure(view, figs, i, world))
        except SlamtrialsError as exc:
            problems.append(f"{world}: a run folder could not be read ({exc})")
            log.warning("Fig. 4 of %s: %s", world, exc)
    return h.section(
        _TITLE,
        h.notes(problems),
        *pictures,
        id=SECTION_ID,
        intro="The metric should tell a good map from a bad one (the paper's Fig. 4): per world, in the order of "
        "Table I, the map and trajectories of the run with the smallest and the largest translational error "
        f"{SYMBOLS['eps_t']} (as the catalog records it).",
    )


def _world_figure(view: CampaignView, figs: FigureWriter, i: int, world: str) -> str:
    """The figure of the ``i``-th world of the page: its best and worst run (by ``eps_t``).

    Raises
    ------
    SlamtrialsError
        A run folder cannot be read (nothing is saved then).
    """
    mine = view.done[view.done["world"] == world]  # in run order: a tie goes to the lower run index
    best, worst = mine.loc[mine["eps_t"].idxmin()], mine.loc[mine["eps_t"].idxmax()]
    picks = [("best", best)] if best["run"] == worst["run"] else [("best", best), ("worst", worst)]
    width = PAGE_WIDTH_IN if len(picks) == 2 else PAGE_WIDTH_IN / 2
    fig = figs.new(width, 6.0)
    axes = np.atleast_1d(fig.subplots(1, len(picks)))
    fits = [_panel(ax, view.read_record(world, int(row["run"])), label, row) for ax, (label, row) in zip(axes, picks)]
    handles, labels = axes[0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncols=len(handles), fontsize=10, frameon=False)
    # the panels' height follows the maps' shape, so a wide or a tall building fills the page's width
    x0, x1 = axes[0].get_xlim()
    y0, y1 = axes[0].get_ylim()
    aspect = (y1 - y0) / (x1 - x0) if x1 > x0 else 1.0
    fig.set_size_inches(width, float(np.clip((width / len(picks) - 0.9) * aspect + 1.5, 3.5, 11.0)))
    caption = _caption(world, picks, len(mine), [fit for fit in fits if fit is not None])
    return figs.save(fig, f"fig4_{i:03d}_{world}", caption, id=f"fig-4-{safe_name(world)}")


def _panel(ax, record: RunRecord, label: str, row: pd.Series) -> TruthAlignment | None:
    """One run of Fig. 4: its map with both trajectories (map frame); the alignment, or None without an estimate."""
    title = (
        f"{label}: run #{int(row['run'])}, {SYMBOLS['eps_t']} {row['eps_t']:.3f} m, "
        f"{SYMBOLS['eps_r']} {row['eps_r']:.4f} rad"
    )
    estimate = None if record.estimate is None else np.asarray(record.estimate, dtype=np.float64)
    if estimate is None or not np.isfinite(estimate).all(axis=1).any():
        if record.map is not None:
            cf.draw_map(ax, record.map, title=title)
            cf.zoom_to_known(ax, record.map)
        message = "no estimate recorded" if estimate is None else "the estimate has no finite pose"
        ax.text(0.5, 0.5, message, ha="center", va="center", transform=ax.transAxes)
        ax.set_title(title, fontsize=11)
        return None
    fit = cf.draw_run_on_map(ax, record.map, record.truth, estimate, title=title, legend=False)
    ax.set_title(title, fontsize=11)
    return fit


def _caption(world: str, picks: list[tuple[str, pd.Series]], runs: int, fits: list[TruthAlignment]) -> str:
    """The caption of a world's figure: the runs shown with their errors, how the truth was placed, its residuals."""
    described = " and ".join(
        f"the {label} run #{int(row['run'])} ({SYMBOLS['eps_t']} {row['eps_t']:.3f} m"
        + (f" over {int(row['relations']):,} relations" if pd.notna(row["relations"]) else "")
        + f", {SYMBOLS['eps_r']} {row['eps_r']:.4f} rad)"
        for label, row in picks
    )
    residuals = [f"{fit.rms:.3f} m" for fit in fits]
    how = (
        "moved into the map frame through the first poses (the truth does not move)"
        if {fit.method for fit in fits} == {"first pose"}
        else "moved into the map frame by a least-squares SE(2) fit (rotation and translation, no scale) of "
        "the true positions onto the estimated ones"
    )
    return (
        f"{world}: the final SLAM map of {described}, the lowest and highest {SYMBOLS['eps_t']} of its "
        f"{runs} runs. On each map, in the map frame: the SLAM estimate as recorded (red; dot: its "
        f"start) and the ground truth (wide, blue) {how}"
        + (
            f"; after the fit the true positions lie {' and '.join(residuals)} (rms) from the estimate."
            if residuals
            else "."
        )
    )
