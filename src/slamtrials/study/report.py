"""``build_study_report``: the study page, ``<study>/report/index.html`` with its figures and tables.

Sections: the study (base campaign, axes, combinations, cells); per world, the mean errors ``eps_t``
(m) and ``eps_r`` (rad) with their intervals against each axis; the table of every cell (also
``cells.csv``); the paired comparisons between neighbouring values of each axis, corrected over the
study (:mod:`slamtrials.study.comparisons`; also ``comparisons.csv``); per world, the SLAM's CPU time
and peak memory per run against the error. Each cell's own campaign report is one
``slamtrials report <study>/cells/<cell>`` away.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from slamtrials.atomicfile import atomic_write, atomic_write_text
from slamtrials.report import html as h
from slamtrials.report.campaign_figures import save_figure
from slamtrials.report.compare import A_BETTER, B_BETTER, Correction
from slamtrials.report.load import CampaignData, load_campaign
from slamtrials.report.tables import METRICS
from slamtrials.study.cells import CELLS_DIR, Cell, expand_cells
from slamtrials.study.comparisons import IDENTICAL_RULE, compare_neighbours
from slamtrials.study.config import value_text
from slamtrials.study.figures import SYMBOLS, UNITS, draw_cost_against_error, draw_error_against_axis
from slamtrials.study.folder import read_manifest
from slamtrials.study.tables import cells_table, finished_runs

__all__ = ["StudyPage", "build_study_report", "REPORT_DIR", "CELLS_CSV", "COMPARISONS_CSV"]

REPORT_DIR = "report"
CELLS_CSV = "cells.csv"
COMPARISONS_CSV = "comparisons.csv"
_FIGURES = "figures"
_COSTS = ("slam_cpu_s_mean", "slam_peak_mib_mean")


@dataclass(frozen=True)
class StudyPage:
    """What :func:`build_study_report` wrote and what it found.

    Attributes
    ----------
    page, cells_csv, comparisons_csv:
        The HTML page and the two tables.
    figures:
        The PNG files of the figures.
    summary_lines:
        Sentences for the terminal: the cells reported and every significant comparison.
    """

    page: Path
    cells_csv: Path
    comparisons_csv: Path
    figures: tuple[Path, ...]
    summary_lines: tuple[str, ...]


class _Figures:
    """Saves figures as ``<out>/figures/<name>.png`` (and ``.pdf``) and makes their ``<figure>`` markup."""

    def __init__(self, out: Path, pdf: bool):
        self.out, self.pdf = out, pdf
        self.written: list[Path] = []

    def save(self, fig, name: str, caption: str) -> str:
        base = self.out / _FIGURES / name
        if self.pdf:
            png, pdf = save_figure(fig, base, dpi=100)
        else:
            png = atomic_write(base.with_name(base.name + ".png"), lambda f: fig.savefig(f, format="png", dpi=100))
            pdf = None
        self.written.append(png)
        rel = lambda p: p.relative_to(self.out).as_posix()  # noqa: E731
        return h.figure(rel(png), caption, pdf=rel(pdf) if pdf else None)


def _safe(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "._-" else "_" for ch in name)


def _new_figure(width: float, height: float):
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), dpi=100, layout="constrained")


def _axis_rows(table: pd.DataFrame, keys: list[str], key: str) -> pd.DataFrame:
    """The product cells' rows with ``others``: the other axes' values as text (the line they are on)."""
    rows = table[~table["combination"]].copy()
    others = [k for k in keys if k != key]
    rows["others"] = [", ".join(f"{k}={r[k]}" for k in others) for _, r in rows.iterrows()]
    return rows


def _error_figures(figs: _Figures, table: pd.DataFrame, config: Any, worlds: list[str]) -> str:
    keys = list(config.axes)
    if not (config.product and keys):
        return h.notes(["The study has no product of axes (only named combinations): see the table of cells."])
    parts = []
    for world in worlds:
        fig = _new_figure(4.2 * len(keys), 6.0)
        axes = fig.subplots(2, len(keys), squeeze=False)
        for column, key in enumerate(keys):
            rows = _axis_rows(table[table["world"] == world], keys, key)
            values = [value_text(v) for v in config.axes[key]]
            for row, metric in enumerate(METRICS):
                draw_error_against_axis(axes[row][column], rows, key, values, metric)
        fig.suptitle(world)
        parts.append(
            figs.save(
                fig,
                f"error-{_safe(world)}",
                f"{world}: mean \u03b5t (m) and \u03b5r (rad) with their intervals at each value of each axis "
                "(one line per combination of the other axes' values).",
            )
        )
    return '<div class="gallery">' + "\n".join(parts) + "</div>"


def _cost_figures(figs: _Figures, table: pd.DataFrame, worlds: list[str]) -> str:
    parts = []
    for world in worlds:
        rows = table[table["world"] == world]
        fig = _new_figure(9.0, 3.6)
        axes = fig.subplots(1, len(_COSTS), squeeze=False)[0]
        for ax, cost in zip(axes, _COSTS, strict=True):
            draw_cost_against_error(ax, rows, cost, "eps_t")
        fig.suptitle(world)
        parts.append(
            figs.save(
                fig,
                f"cost-{_safe(world)}",
                f"{world}: each cell's mean \u03b5t (m, with its interval) against the SLAM's mean CPU time (s) and "
                "peak memory (MiB) per run.",
            )
        )
    return '<div class="gallery">' + "\n".join(parts) + "</div>"


def _num(value: Any, digits: int = 3) -> h.Cell:
    return h.Cell(h.fmt_number(value, digits), numeric=True)


def _interval(low: Any, high: Any, digits: int) -> h.Cell:
    if low is None or high is None or not (math.isfinite(float(low)) and math.isfinite(float(high))):
        return h.Cell("-", numeric=True)
    return h.Cell(f"[{float(low):.{digits}f}, {float(high):.{digits}f}]", numeric=True)


def _cells_section(table: pd.DataFrame, keys: list[str]) -> str:
    header = [
        "cell",
        *keys,
        "world",
        "status",
        "runs",
        "\u03b5t mean (m)",
        "interval",
        "\u03b5r mean (rad)",
        "interval",
    ]
    header += ["SLAM CPU s", "SLAM MiB", "ms / update"]
    rows = []
    for _, r in table.iterrows():
        rows.append(
            [
                r["cell"],
                *[r[k] for k in keys],
                r["world"],
                r["status"] + (" (capped)" if bool(r["capped"]) else ""),
                int(r["runs"]),
                _num(r["eps_t_mean"], 3),
                _interval(r["eps_t_ci_low"], r["eps_t_ci_high"], 3),
                _num(r["eps_r_mean"], 4),
                _interval(r["eps_r_ci_low"], r["eps_r_ci_high"], 4),
                _num(r["slam_cpu_s_mean"], 1),
                _num(r["slam_peak_mib_mean"], 1),
                _num(r["update_ms_median_mean"], 2),
            ]
        )
    confidence = table["confidence"].dropna()
    level = f"{100 * float(confidence.iloc[0]):g} %" if len(confidence) else "the campaigns'"
    return h.table(header, rows, caption=f"Every cell and world: intervals at {level}; cost means per run.")


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")


def _verdict_text(row: pd.Series) -> str:
    if bool(row.get("identical", False)):
        return "identical runs"
    if row["verdict"] == A_BETTER:
        return f"{row['axis']}={row['value_a']} better"
    if row["verdict"] == B_BETTER:
        return f"{row['axis']}={row['value_b']} better"
    return str(row["verdict"])


def _comparisons_section(comparisons: pd.DataFrame, levels: dict, alpha: float, correction: str) -> str:
    if comparisons.empty:
        return h.notes(["No neighbouring cells with finished runs to compare yet."])
    parts = []
    for metric in METRICS:
        rows = comparisons[comparisons["metric"] == metric]
        if rows.empty:
            continue
        digits = 3 if metric == "eps_t" else 4
        header = ["axis", "step A \u2192 B", "other axes", "world", "test", "pairs"]
        header += [f"B \u2212 A ({UNITS[metric]})", "adjusted interval", "p adj", "Wilcoxon p adj", "verdict"]
        body = [
            [
                r["axis"],
                f"{r['value_a']} \u2192 {r['value_b']}",
                r["others"] or "-",
                r["world"],
                r["test"],
                int(r["n_a"]),
                _num(r["difference"], digits),
                _interval(r["ci_adj_low"], r["ci_adj_high"], digits),
                _num(r["p_adjusted"], 3),
                _num(r["wilcoxon_p_adjusted"], 3),
                _verdict_text(r),
            ]
            for _, r in rows.iterrows()
        ]
        level = levels.get(metric)
        identical = int(rows["identical"].sum()) if "identical" in rows else 0
        family = len(rows) - identical
        caption = (
            f"{SYMBOLS[metric]}: paired t-tests of run k of B against run k of A (the cells of a world share their "
            f"seeds), {correction} over the study's {_count(family, 'comparison')} of {SYMBOLS[metric]} at "
            f"\u03b1 = {alpha:g}"
            + (f" ({_count(identical, 'comparison')} of identical runs left out)" if identical else "")
            + (f"; intervals {level.label}" if level is not None else "")
            + "."
        )
        parts.append(h.table(header, body, caption=caption))
    rule = (
        f"The correction ({correction}) runs per metric over every axis step, combination of the other axes and "
        f"world of the study: one family. {IDENTICAL_RULE}"
    )
    return h.notes([rule]) + "\n" + "\n".join(parts)


def _summary_lines(comparisons: pd.DataFrame, table: pd.DataFrame, cells: list[Cell]) -> list[str]:
    lines = [f"{len(cells)} cells, {table['world'].nunique() if len(table) else 0} worlds, {len(table)} rows"]
    if comparisons.empty:
        return [*lines, "no paired comparisons yet"]
    significant = comparisons[comparisons["verdict"].isin((A_BETTER, B_BETTER))]
    identical = int(comparisons["identical"].sum())
    lines.append(
        f"{len(significant)} of {len(comparisons)} paired comparisons significant after correction"
        + (f" ({identical} of identical runs, left out of the correction)" if identical else "")
    )
    for _, r in significant.iterrows():
        unit = UNITS[r["metric"]]
        lines.append(
            f"{r['world']}, {r['metric']}: {r['axis']} {r['value_a']} -> {r['value_b']}"
            + (f" ({r['others']})" if r["others"] else "")
            + f": {r['difference']:+.4f} {unit} (p adj {r['p_adjusted']:.3g}): {_verdict_text(r)}"
        )
    return lines


def build_study_report(
    folder: str | Path,
    out: str | Path | None = None,
    *,
    alpha: float = 0.05,
    correction: Correction = "holm",
    pdf: bool = True,
) -> StudyPage:
    """Write the study page of the study in ``folder`` (see the module docstring); it only reads the study.

    Parameters
    ----------
    folder:
        The study folder (finished or not).
    out:
        Folder of the page, figures and tables (default ``<folder>/report``).
    alpha, correction:
        Significance level and multiple-comparison correction of the paired comparisons.
    pdf:
        Also write each figure as PDF.

    Raises
    ------
    ConfigError
        ``folder`` holds no study.
    """
    folder = Path(folder).absolute()
    manifest = read_manifest(folder)
    config = manifest.config
    cells = expand_cells(config)
    out = Path(out).absolute() if out is not None else folder / REPORT_DIR
    data: dict[str, CampaignData] = {}
    for cell in cells:
        cell_folder = folder / CELLS_DIR / cell.name
        if (cell_folder / "campaign.sqlite").is_file():
            data[cell.name] = load_campaign(cell_folder)
    keys = list(dict.fromkeys([*config.axes, *(k for c in config.combinations.values() for k in c)]))
    table = cells_table(cells, keys, data)
    runs = {name: finished_runs(d) for name, d in data.items()}
    comparisons, levels = compare_neighbours(cells, config.axes, runs, alpha=alpha, correction=correction)
    out.mkdir(parents=True, exist_ok=True)
    cells_csv = atomic_write_text(out / CELLS_CSV, table.to_csv(index=False))
    comparisons_csv = atomic_write_text(out / COMPARISONS_CSV, comparisons.to_csv(index=False))
    worlds = list(dict.fromkeys(table["world"])) if len(table) else []
    figs = _Figures(out, pdf)
    base = config.base()
    overview = h.definition_list(
        [
            ("study folder", str(folder)),
            ("worlds", ", ".join(worlds) or "-"),
            (
                "base campaign",
                f"{base.slam.algorithm} (preset {base.slam.preset}), profile {base.sim.profile_label}, "
                f"seed {base.seed}, runs: initial {base.runs.initial}, cap {base.runs.max_runs}, margins "
                f"{base.runs.margin_t:g} m / {base.runs.margin_r:g} rad at {100 * base.runs.confidence:g} %",
            ),
            ("axes", "; ".join(f"{k}: {', '.join(value_text(v) for v in vs)}" for k, vs in config.axes.items()) or "-"),
            ("combinations", "; ".join(f"{n}: {c}" for n, c in config.combinations.items()) or "-"),
            ("cells", ", ".join(c.name for c in cells)),
            ("created", manifest.created),
        ]
    )
    capped = sorted({r["cell"] for _, r in table.iterrows() if bool(r["capped"])}) if len(table) else []
    remarks = []
    if capped:
        remarks.append(
            f"Capped at {base.runs.max_runs} runs per world (the margins are not reached) in: {', '.join(capped)}; "
            "their intervals are wider than the study's margins."
        )
    missing = [c.name for c in cells if c.name not in data]
    if missing:
        remarks.append(f"Not started yet: {', '.join(missing)}.")
    body = [
        h.section("Study", overview, h.notes(remarks), id="study"),
        h.section("Error against each axis", _error_figures(figs, table, config, worlds), id="axes"),
        h.section("Every cell", _cells_section(table, keys), id="cells"),
        h.section(
            "Paired comparisons of neighbouring values",
            _comparisons_section(comparisons, levels, alpha, correction),
            id="comparisons",
        ),
        h.section("Cost against error", _cost_figures(figs, table, worlds), id="cost"),
    ]
    nav = [
        ("study", "Study"),
        ("axes", "Error per axis"),
        ("cells", "Cells"),
        ("comparisons", "Comparisons"),
        ("cost", "Cost"),
    ]
    page = atomic_write_text(
        out / "index.html",
        h.page(f"Study {folder.name}", body, subtitle=f"{len(cells)} cells over {len(worlds)} worlds", nav=nav),
    )
    return StudyPage(
        page, cells_csv, comparisons_csv, tuple(figs.written), tuple(_summary_lines(comparisons, table, cells))
    )
