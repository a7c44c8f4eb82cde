"""The HTML report of a campaign: :func:`build_report`, which assembles the page's sections in order.

:func:`build_report` reads a campaign folder (read-only, :func:`slamtrials.report.load.load_campaign` and
the run folders) into a :class:`~slamtrials.report.campaign_view.CampaignView`, lets each section draw its
figures (:class:`~slamtrials.report.figure_writer.FigureWriter`: ``matplotlib.figure.Figure`` objects, no
pyplot, so any backend works) and writes ``<out>/index.html`` with every figure beside it in
``<out>/figures/`` as PNG (shown) and PDF (linked). The sections, each its own module, in page order:

* the overview: settings, run times, notes on what is missing (:mod:`~slamtrials.report.overview`);
* Table I: per world, runs, mean, standard deviation and confidence interval of ``eps_t`` (m) and
  ``eps_r`` (rad), the metric's share of the between-run variance, outlier counts and the mean cost per run
  (``<table id="summary-table">``, one row per world in the campaign's order, which every figure keeps),
  and the paper's printed layout (:mod:`~slamtrials.report.table_one`);
* Fig. 1: each world's run errors, largest first, and all worlds' sorted curves
  (:mod:`~slamtrials.report.run_errors`);
* Fig. 5: all runs of all worlds, outliers (Tukey's fences) marked (:mod:`~slamtrials.report.all_runs`);
* Fig. 6: pairs of worlds where a single run of each would rank them opposite to their means
  (:mod:`~slamtrials.report.world_traps`);
* Fig. 3: the relation-sampling check of one run: the mean error over repeated samplings, with a normal fit
  (:mod:`~slamtrials.report.sampling_check`);
* Fig. 4: the best and the worst map of every world (by ``eps_t``), the estimated trajectory on the map
  (map frame) and the true one fitted onto it (:mod:`~slamtrials.report.best_worst_maps`);
* termination reasons and explored fraction of the runs (:mod:`~slamtrials.report.termination`);
* what the runs cost: CPU time and peak memory of the SLAM algorithm and of the whole run, and the time
  per SLAM update (:mod:`~slamtrials.report.cost`);
* how fast the runs explored: coverage curves, time and distance to 90 % and 99 % coverage
  (:mod:`~slamtrials.report.exploration`);
* how well the final maps draw the floor plans: per world, the mean occupied-cell precision and recall
  within 1 and 2 cells, free-space IoU and ghost area (:mod:`~slamtrials.report.map_quality`);
* every run (seed, status, errors, outlier marks) (:mod:`~slamtrials.report.runs_table`), and the
  provenance: config, root seed, versions (:mod:`~slamtrials.report.provenance`).

In every section the figures and tables come first; explanations longer than a couple of sentences follow
them in a collapsed ``<details>`` block. A campaign that is still running, has failed or capped worlds, or
no finished run yet still gives a page, with notes saying what is missing. Every file is written
atomically; figures of an earlier report that are not drawn again are removed.

The page comparing two campaigns is :func:`slamtrials.report.compare_page.compare_report` (also importable
from here, as are the other names this module held before its sections became modules).
"""

from __future__ import annotations

from pathlib import Path

from slamtrials.atomicfile import atomic_write_text
from slamtrials.errors import ConfigError
from slamtrials.report import html as h
from slamtrials.report.all_runs import all_runs_section
from slamtrials.report.best_worst_maps import best_worst_maps_section
from slamtrials.report.campaign_figures import draw_trap_pair
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.compare_page import COMPARE_CSV, COMPARE_PAGE, CompareReport, compare_report, trap_sentences
from slamtrials.report.cost import cost_section
from slamtrials.report.exploration import exploration_section
from slamtrials.report.figure_writer import FIGURES_DIR, FigureWriter
from slamtrials.report.load import load_campaign
from slamtrials.report.map_quality import map_quality_section
from slamtrials.report.overview import overview_section
from slamtrials.report.provenance import provenance_section
from slamtrials.report.run_errors import run_errors_section
from slamtrials.report.runs_table import runs_section
from slamtrials.report.sampling_check import DEFAULT_REPEATS, choose_sampling_run, parse_run, sampling_check_section
from slamtrials.report.table_one import table_one_section
from slamtrials.report.termination import termination_section
from slamtrials.report.world_traps import world_traps_section

__all__ = [
    "build_report",
    "compare_report",
    "CompareReport",
    "parse_run",
    "REPORT_DIR",
    "REPORT_PAGE",
    "COMPARE_PAGE",
    "COMPARE_CSV",
    "FIGURES_DIR",
    "DEFAULT_REPEATS",
    "trap_sentences",
    "draw_trap_pair",
]

REPORT_DIR = "report"
REPORT_PAGE = "index.html"


def build_report(
    campaign_path: str | Path,
    out_dir: str | Path | None = None,
    *,
    sampling_run: str | tuple[str, int] | None = None,
    repeats: int = DEFAULT_REPEATS,
    seed: int = 0,
    pdf: bool = True,
) -> Path:
    """Write the HTML report of a campaign (see the module docstring) and return the path of ``index.html``.

    Parameters
    ----------
    campaign_path:
        The campaign folder (finished or still running; it is only read).
    out_dir:
        Folder of the page and its ``figures/``; default ``<campaign>/report``.
    sampling_run:
        The run of the relation-sampling check (Fig. 3), ``"WORLD/INDEX"`` or ``(world, index)``; default
        the first finished run of the first world that has one.
    repeats:
        Samplings of that check (the paper: 200).
    seed:
        Seed of those samplings.
    pdf:
        Also save every figure as PDF (linked under it).

    Returns
    -------
    Path
        ``<out_dir>/index.html``.

    Raises
    ------
    FormatError
        ``campaign_path`` is not a campaign folder.
    ConfigError
        A bad ``sampling_run`` (unknown or unfinished run) or ``repeats`` below 2.
    """
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 2:
        raise ConfigError(f"repeats must be an integer of at least 2, got {repeats!r}")
    view = CampaignView.of(load_campaign(campaign_path))
    chosen = choose_sampling_run(view, sampling_run)  # a bad --run fails before anything is written
    out = Path(out_dir) if out_dir is not None else view.data.folder / REPORT_DIR
    out.mkdir(parents=True, exist_ok=True)
    figs = FigureWriter(out, "report_", pdf)
    sections = [  # (anchor, label in the table of contents, the section), in page order
        ("overview", "Overview", overview_section(view)),
        ("table-1", "Table I", table_one_section(view)),
        ("fig-1", "Fig. 1", run_errors_section(view, figs)),
        ("fig-5", "Fig. 5", all_runs_section(view, figs)),
        ("fig-6", "Fig. 6", world_traps_section(view, figs)),
        ("fig-3", "Fig. 3", sampling_check_section(view, figs, chosen, repeats=repeats, seed=seed)),
        ("fig-4", "Fig. 4", best_worst_maps_section(view, figs)),
        ("termination", "Termination", termination_section(view, figs)),
        ("cost", "Cost", cost_section(view, figs)),
        ("exploration", "Exploration", exploration_section(view, figs)),
        ("map-quality", "Map quality", map_quality_section(view.done, view.worlds)),
        ("runs", "Runs", runs_section(view.data)),
        ("provenance", "Provenance", provenance_section(view.data)),
    ]
    data = view.data
    title = f"{data.kind.capitalize()} report: {data.folder.name}"
    subtitle = (
        f"SLAM algorithm {data.config.get('slam', {}).get('algorithm')}; {len(data.worlds)} worlds, "
        f"{len(view.done)} finished runs; errors of the Kuemmerle et al. metric on sampled relations "
        "(Amigoni, Castelli, Luperto, IROS 2018)."
    )
    nav = [(anchor, label) for anchor, label, _ in sections]
    page = atomic_write_text(
        out / REPORT_PAGE, h.page(title, [html for _, _, html in sections], subtitle=subtitle, nav=nav)
    )
    figs.clean()
    return page
