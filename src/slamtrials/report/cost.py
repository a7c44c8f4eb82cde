"""The report's section on what the runs cost (:class:`slamtrials.cost.RunCost`): per world, every run's
SLAM CPU time, time per update and SLAM memory drawn (:mod:`slamtrials.report.cost_figures`), a table of
the means, and what each figure is, collapsed under them."""

from __future__ import annotations

import numpy as np

from slamtrials.report import cost_figures as costf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.tables import finite_mean

__all__ = ["cost_section", "COST_TEXT", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "cost"

#: What each cost figure is, as the section explains it.
COST_TEXT = (
    "What the runs cost, measured as they ran (not reproducible: another run of the same campaign costs a "
    "little more or less, so these figures are never part of a result's comparison). SLAM CPU: the CPU time "
    "(user + system) of the SLAM algorithm in the run, its calls timed on the thread's CPU clock, or, for an "
    "external program, its process's own (rusage). Run CPU: the whole run's (simulator, SLAM, explorer, "
    "coverage; with a program, its process too; in a replay, the SLAM algorithm's pass over the recorded "
    "frames). Time per update: the wall time of each SLAM call that made an update, its median and 90th "
    "percentile per run. SLAM memory: the most resident memory the algorithm's calls had added to the process"
    " (its maps, particles or graph and the scratch of its updates; approximate: resident pages, not "
    "allocations, and a worker's first run also counts loading the compiled kernels), or an external "
    "program's peak resident memory. Run memory: the peak resident memory of the worker process during the "
    "run (the Python runtime and libraries included), plus a program's. Tables give the means over the runs; "
    "- where not measured (runs of earlier versions, or a platform without Linux's /proc)."
)

_TITLE = "What the runs cost: CPU time and memory"
_HEADER = [
    "world",
    "runs measured",
    "SLAM CPU s",
    "run CPU s",
    "ms per update (median)",
    "ms per update (p90)",
    "SLAM share of the CPU",
    "SLAM MiB",
    "run MiB",
]


def cost_section(view: CampaignView, figs: FigureWriter) -> str:
    """The section (HTML, ``id="cost"``): the figure (SLAM CPU time, time per update, SLAM memory per run),
    ``<table id="cost-table">`` of the means per world in the order of Table I, then :data:`COST_TEXT`
    collapsed (``id="cost-note"``); a line instead of the figure and table when no run recorded its cost."""
    done, worlds = view.done, view.worlds
    explain = h.details(
        "What these figures are and how they are measured",
        h.explanation(COST_TEXT, id="cost-note"),
        css_class="explain",
    )
    measured = done[np.isfinite(costf.cost_values(done, "slam_cpu_s"))] if len(done) else done
    if measured.empty:
        return h.section(_TITLE, "<p>No finished run recorded its cost.</p>", explain, id=SECTION_ID)
    fig = figs.new(min(max(12.0, 0.9 * len(worlds) + 6), 30), 3.8)
    axes = fig.subplots(1, 3)
    costf.draw_cost_per_world(axes[0], done, "slam_cpu_s", worlds, "SLAM CPU time per run (s)", legend=True)
    costf.draw_update_times(axes[1], done, worlds)
    costf.draw_cost_per_world(axes[2], done, "slam_peak_mib", worlds, "SLAM peak memory (MiB)")
    picture = figs.save(
        fig,
        "cost",
        "Left: the SLAM algorithm's CPU time in each run. Middle: each run's median time per SLAM update (points) "
        "and its 90th percentile (crosses). Right: the SLAM algorithm's peak memory in each run. Bars: the world's "
        "mean. Worlds in the order of Table I.",
    )
    table = h.table(
        _HEADER,
        [_row(view, world) for world in worlds],
        id="cost-table",
        caption="Means over the world's runs; SLAM share of the CPU: the runs' SLAM CPU time over their whole CPU time.",
    )
    return h.section(_TITLE, picture, table, explain, id=SECTION_ID)


def _row(view: CampaignView, world: str) -> list:
    """The cost table's row of ``world``: runs measured, mean CPU times (s), update times (ms), memory (MiB)."""
    mine = view.done[view.done["world"] == world]
    slam_cpu, run_cpu = costf.cost_values(mine, "slam_cpu_s"), costf.cost_values(mine, "run_cpu_s")
    both = np.isfinite(slam_cpu) & np.isfinite(run_cpu) & (run_cpu > 0)
    return [
        world,
        h.Cell(str(int(np.isfinite(slam_cpu).sum())), numeric=True),
        *[
            h.seconds_cell(finite_mean(costf.cost_values(mine, name)))
            for name in ("slam_cpu_s", "run_cpu_s", "update_ms_median", "update_ms_p90")
        ],
        h.Cell(f"{100 * slam_cpu[both].sum() / run_cpu[both].sum():.0f} %" if both.any() else "-", numeric=True),
        *[h.seconds_cell(finite_mean(costf.cost_values(mine, name))) for name in ("slam_peak_mib", "run_peak_mib")],
    ]
