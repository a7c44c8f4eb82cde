"""The HTML page that compares two campaigns on their common worlds: :func:`compare_report`.

The statistics are :func:`slamtrials.report.compare.compare_campaigns` (paired tests when one campaign is a
replay of the other or both share their recorded data, Welch's otherwise; corrected p-values with intervals
corrected alike, verdicts, Stouffer's overall test, the Fig. 6 trap). The page ``compare.html`` has four
sections: the two campaigns and how they were tested, the overall verdict, the per-world tables
(:mod:`slamtrials.report.compare_table`) with their forest plots, and the worlds where single runs would give
the opposite verdict; ``comparison.csv`` holds the table and ``figures/`` the pictures.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from slamtrials.atomicfile import atomic_write_text
from slamtrials.campaign.differences import campaign_differences
from slamtrials.campaign.events import REPLAY_NOTE
from slamtrials.errors import ConfigError
from slamtrials.report import campaign_figures as cf
from slamtrials.report import html as h
from slamtrials.report.campaign_view import finished_runs
from slamtrials.report.compare import Comparison, Correction, compare_campaigns, comparison_notes
from slamtrials.report.compare_table import comparison_table
from slamtrials.report.figure_writer import FigureWriter
from slamtrials.report.load import CampaignData, load_campaign
from slamtrials.report.pairing import detect_pairing
from slamtrials.report.tables import METRICS, SYMBOLS, UNITS

__all__ = ["compare_report", "CompareReport", "trap_sentences", "COMPARE_PAGE", "COMPARE_CSV"]

COMPARE_PAGE = "compare.html"
COMPARE_CSV = "comparison.csv"
#: Worlds in the picture of the Fig. 6 trap at the most (most reversed first).
MAX_TRAP_WORLDS = 12


@dataclass(frozen=True)
class CompareReport:
    """What :func:`compare_report` wrote and found.

    Attributes
    ----------
    comparison:
        The statistics (:class:`slamtrials.report.compare.Comparison`).
    page, table_csv:
        ``compare.html`` and ``comparison.csv``.
    figures:
        The figure files (PNG and PDF).
    notes:
        Remarks shown on the page (worlds in one campaign only, replay pairing, unfinished campaigns).
    folders:
        The two campaign folders (A, B).
    """

    comparison: Comparison
    page: Path
    table_csv: Path
    figures: tuple[Path, ...] = ()
    notes: tuple[str, ...] = ()
    folders: tuple[Path, Path] = field(default=(Path("."), Path(".")))


def compare_report(
    campaign_a: str | Path,
    campaign_b: str | Path,
    out_dir: str | Path,
    *,
    alpha: float = 0.05,
    correction: Correction = "holm",
    labels: tuple[str, str] | None = None,
    pdf: bool = True,
) -> CompareReport:
    """Compare campaign B with campaign A on their common worlds and write ``compare.html`` into ``out_dir``.

    Parameters
    ----------
    campaign_a, campaign_b:
        The two campaign folders (e.g. two SLAM algorithms on the same worlds, or a campaign and its replay).
    out_dir:
        Folder of ``compare.html``, ``comparison.csv`` and ``figures/``.
    alpha:
        Significance level of the verdicts; each world's own interval has confidence ``1 - alpha``, the
        one beside the verdicts the level that matches ``correction``.
    correction:
        ``"holm"``, ``"bh"`` or ``"none"``: correction of the p-values (and of the intervals beside them) for
        multiple comparisons (per metric, across worlds). The runs are paired when one campaign is a replay
        of the other or both of one source (:func:`slamtrials.report.pairing.detect_pairing`).
    labels:
        Names of A and B on the page; default the folder names.
    pdf:
        Also save every figure as PDF.

    Raises
    ------
    FormatError
        A folder is not a campaign.
    ConfigError
        A campaign has no finished run, the two have no world in common, or a bad ``alpha`` / ``correction``.
    """
    data_a, data_b = load_campaign(campaign_a), load_campaign(campaign_b)
    done_a, done_b = finished_runs(data_a), finished_runs(data_b)
    for data, done, name in ((data_a, done_a, "A"), (data_b, done_b, "B")):
        if done.empty:
            raise ConfigError(f"{data.folder}: campaign {name} has no finished run to compare")
    names = labels or _labels(data_a, data_b)
    pairing = detect_pairing(data_a, data_b, names)
    try:
        comparison = compare_campaigns(
            done_a, done_b, alpha=alpha, correction=correction, labels=names, paired_by=pairing.paired_by
        )
    except ValueError as exc:
        raise ConfigError(f"cannot compare {data_a.folder} with {data_b.folder}: {exc}") from None
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figs = FigureWriter(out, "compare_", pdf)
    notes = _compare_notes(data_a, data_b, comparison, pairing.note)
    forest = [_forest_figure(figs, comparison, metric) for metric in METRICS]
    trap_picture = _trap_figure(figs, comparison, done_a, done_b)
    csv_text = io.StringIO()
    comparison.table.to_csv(csv_text, index=False, lineterminator="\n")
    table_csv = atomic_write_text(out / COMPARE_CSV, csv_text.getvalue())
    name_a, name_b = comparison.labels
    body = [
        _campaigns_section(data_a, data_b, comparison, notes),
        h.section(
            "Overall verdict",
            '<ul id="overall">'
            + "".join(
                f"<li>{h.esc(f'{SYMBOLS[m]}: {comparison.overall[m].statement}')}</li>"
                for m in METRICS
                if m in comparison.overall
            )
            + "</ul>",
            id="verdict",
        ),
        h.section(
            "Per world",
            *(comparison_table(comparison, m) for m in METRICS),
            f'<p><a href="{COMPARE_CSV}">comparison.csv</a></p>',
            *forest,
            id="per-world",
        ),
        _trap_section(comparison, trap_picture),
    ]
    nav = [("campaigns", "Campaigns"), ("verdict", "Verdict"), ("per-world", "Per world"), ("trap", "Fig. 6 trap")]
    page = atomic_write_text(
        out / COMPARE_PAGE,
        h.page(
            f"Comparison: {name_b} vs {name_a}",
            body,
            subtitle="Lower errors are better; differences are B \u2212 A.",
            nav=nav,
        ),
    )
    figs.clean()
    return CompareReport(comparison, page, table_csv, tuple(figs.written), tuple(notes), (data_a.folder, data_b.folder))


def _labels(a: CampaignData, b: CampaignData) -> tuple[str, str]:
    """The campaigns' names on the page: their folders' names, or ``A`` and ``B`` when those are the same."""
    names = (a.folder.name, b.folder.name)
    return names if names[0] != names[1] else ("A", "B")


def _compare_notes(a: CampaignData, b: CampaignData, comparison: Comparison, unpaired_because: str = "") -> list[str]:
    """The remarks of the page: worlds of one campaign only, how the runs were paired (or why not), the
    comparison's own notes, and campaigns that have not finished."""
    notes = []
    name_a, name_b = comparison.labels
    if comparison.only_a:
        notes.append(f"Worlds only in {name_a}, not compared: {', '.join(comparison.only_a)}.")
    if comparison.only_b:
        notes.append(f"Worlds only in {name_b}, not compared: {', '.join(comparison.only_b)}.")
    if comparison.paired:
        notes.append(
            f"{comparison.pairing[0].upper()}{comparison.pairing[1:]}: run i of a world comes from the same recorded "
            "data in both campaigns, so each world is tested on the run-by-run differences (paired t-test, with "
            "the Wilcoxon signed-rank test as a check). "
            + (REPLAY_NOTE + "." if "replay" in comparison.pairing else "")
        )
    elif unpaired_because:
        notes.append(f"Unpaired: {unpaired_because}.")
    notes.extend(comparison_notes(comparison))
    for data, name in ((a, name_a), (b, name_b)):
        unfinished = data.worlds[~data.worlds["status"].isin(["done", "capped", "short"])]
        if len(unfinished):
            notes.append(
                f"{name} is not finished ({', '.join(f'{w} {s}' for w, s in zip(unfinished['world'], unfinished['status']))}): "
                "the comparison uses the runs done so far."
            )
    return notes


def trap_sentences(comparison: Comparison, metric: str = "eps_t") -> list[str]:
    """One sentence per world where a single run of each campaign would give the opposite verdict to the means
    (the paper's Fig. 6 trap), most reversed first."""
    name_a, name_b = comparison.labels
    unit = UNITS[metric]
    out = []
    rows = comparison.for_metric(metric)
    for _, r in rows.sort_values("trap_fraction", ascending=False, na_position="last", kind="stable").iterrows():
        diff = r["difference"]
        if diff == 0 or not np.sign(r["trap_difference"]) == -np.sign(diff):
            continue
        better, worse = (name_b, name_a) if diff < 0 else (name_a, name_b)
        if comparison.paired:  # the same run replayed by both sides
            single = (
                f"but run #{r['trap_run_a']} alone ({name_a}: {r['trap_value_a']:.3f} {unit}, "
                f"{name_b}: {r['trap_value_b']:.3f} {unit}) gives the opposite verdict; "
                f"{r['trap_fraction']:.0%} of the runs do."
            )
        else:
            single = (
                f"but its run alone against one run of {worse} ({name_a} #{r['trap_run_a']}: {r['trap_value_a']:.3f} "
                f"{unit}, {name_b} #{r['trap_run_b']}: {r['trap_value_b']:.3f} {unit}) gives the opposite verdict; "
                f"{r['trap_fraction']:.0%} of all single-run pairs do."
            )
        out.append(
            f"{r['world']}: {better} has the lower mean {SYMBOLS[metric]} (by {abs(diff):.3g} {unit}; verdict: "
            f"{r['verdict']}), {single}"
        )
    return out


def _campaigns_section(a: CampaignData, b: CampaignData, comparison: Comparison, notes: list[str]) -> str:
    """The first section (``id="campaigns"``): both campaigns, the settings that differ, the compared worlds,
    the tests, and the page's notes."""
    name_a, name_b = comparison.labels

    def describe(d: CampaignData) -> str:
        return (
            f"{d.folder} ({d.kind}, {d.config.get('slam', {}).get('algorithm')}, "
            f"{int((d.runs['status'] == 'done').sum())} finished runs)"
        )

    differences = campaign_differences(a.folder, b.folder)
    test = (
        f"{comparison.pairing}: "
        + (
            "paired t-test per world (Wilcoxon signed-rank as a check)"
            if comparison.paired
            else "Welch's t-test per world"
        )
        + f", {comparison.correction} correction across worlds, \u03b1 = {comparison.alpha:g}; intervals: "
        + "; ".join(f"{SYMBOLS[m]} {comparison.intervals[m].label}" for m in METRICS if m in comparison.intervals)
        + "; overall: "
        + (comparison.overall[METRICS[0]].test if METRICS[0] in comparison.overall else "-")
        + " (sign test over worlds as a check)"
    )
    return h.section(
        "Campaigns",
        h.definition_list(
            [
                (f"A = {name_a}", describe(a)),
                (f"B = {name_b}", describe(b)),
                ("settings that differ (A -> B)", "; ".join(map(str, differences)) or "none"),
                ("compared worlds", ", ".join(comparison.for_metric(METRICS[0])["world"])),
                ("test", test),
            ]
        ),
        h.notes(notes, id="notes"),
        id="campaigns",
    )


def _forest_figure(figs: FigureWriter, comparison: Comparison, metric: str) -> str:
    """The forest plot of ``metric``: B - A per world with its corrected interval, coloured by verdict."""
    name_a, name_b = comparison.labels
    fig = figs.new(8.5, max(2.8, 0.42 * len(comparison.for_metric(metric)) + 1.8))
    cf.draw_comparison(fig.subplots(), comparison, metric)
    return figs.save(
        fig,
        f"forest_{metric}",
        f"{name_b} \u2212 {name_a} in mean {SYMBOLS[metric]} per world ({comparison.pairing}) with "
        f"{comparison.intervals[metric].label} intervals, coloured by verdict ({comparison.correction} correction); "
        "diamonds: the most misleading single-run pair where it contradicts the means; right margin: share "
        "of run pairs that reverse the means.",
    )


def _trap_figure(figs: FigureWriter, comparison: Comparison, done_a: pd.DataFrame, done_b: pd.DataFrame) -> str:
    """The Fig. 6 trap between the campaigns on ``eps_t``: per world (most reversed first, at most
    :data:`MAX_TRAP_WORLDS`) the runs of each and the most misleading pair; ``""`` when no world has one."""
    trap_rows = comparison.for_metric("eps_t")
    trap_rows = (
        trap_rows[np.isfinite(trap_rows["trap_fraction"])]
        .sort_values("trap_fraction", ascending=False, kind="stable")
        .head(MAX_TRAP_WORLDS)
    )
    if not len(trap_rows):
        return ""
    name_a, name_b = comparison.labels
    ncols = min(4, len(trap_rows))
    nrows = math.ceil(len(trap_rows) / ncols)
    fig = figs.new(3.3 * ncols, 3.0 * nrows)
    axes = np.atleast_1d(fig.subplots(nrows, ncols)).reshape(-1)
    for ax, (_, r) in zip(axes, trap_rows.iterrows()):
        a = done_a[done_a["world"] == r["world"]]
        b = done_b[done_b["world"] == r["world"]]
        if comparison.paired:  # the runs the paired test compared
            a, b = a[a["run"].isin(b["run"])], b[b["run"].isin(a["run"])]
        ia = int(np.flatnonzero(a["run"].to_numpy() == r["trap_run_a"])[0])
        ib = int(np.flatnonzero(b["run"].to_numpy() == r["trap_run_b"])[0])
        va, vb = a["eps_t"].to_numpy(), b["eps_t"].to_numpy()
        color_a, color_b = "tab:blue", "tab:orange"
        if vb.mean() < va.mean():
            cf.draw_trap_pair(ax, vb, va, (name_b, name_a), ib, ia, colors=(color_b, color_a))
        else:
            cf.draw_trap_pair(ax, va, vb, (name_a, name_b), ia, ib, colors=(color_a, color_b))
        ax.set_title(f"{r['world']}: {r['verdict']}\n{r['trap_fraction']:.0%} of run pairs reversed", fontsize=8)
    for ax in axes[len(trap_rows) :]:
        ax.set_visible(False)
    return figs.save(
        fig,
        "trap",
        "The paper's Fig. 6 trap between the two campaigns: per world (most reversed "
        "first), the runs of each and their means (A blue, B orange, the lower mean on the "
        "left); ringed and joined: the single-run pair that contradicts the means the most.",
    )


def _trap_section(comparison: Comparison, picture: str) -> str:
    """The last section (``id="trap"``): a sentence per world where single runs reverse the verdict, and ``picture``."""
    traps = trap_sentences(comparison)
    return h.section(
        "Fig. 6: where single runs would give the opposite verdict",
        "<ul>" + "".join(f"<li>{h.esc(s)}</li>" for s in traps) + "</ul>"
        if traps
        else "<p>No world has a single-run pair that contradicts its means.</p>",
        picture,
        id="trap",
    )
