"""The HTML report of a campaign (:func:`build_report`) and of a comparison of two (:func:`compare_report`).

:func:`build_report` reads a campaign folder (read-only, :func:`slamtrials.report.load.load_campaign` and
the run folders), draws the paper's figures with :mod:`slamtrials.report.campaign_figures` on
``matplotlib.figure.Figure`` objects (no pyplot, so any backend works) and writes
``<out>/index.html`` with every figure beside it in ``<out>/figures/`` as PNG (shown) and PDF (linked):

* Table I: per world, runs, mean, standard deviation and confidence interval of ``eps_t`` (m) and
  ``eps_r`` (rad), the metric's share of the between-run variance of each, the outlier counts and the
  mean cost per run (SLAM CPU time, time per update, SLAM memory), with a
  paragraph saying what the share and the outlier column are (``<table id="summary-table">``, one row per
  world, in the campaign's order, which every figure keeps), and the paper's printed layout;
* Fig. 1: each world's run errors, largest first, and all worlds' sorted curves;
* Fig. 5: all runs of all worlds, outliers (Tukey's fences) marked;
* Fig. 6: pairs of worlds where a single run of each would rank them opposite to their means;
* Fig. 3: the relation-sampling check of one run: the mean error over repeated samplings, with a normal fit;
* Fig. 4: the best and the worst map of every world (by ``eps_t``) with their errors, the estimated
  trajectory drawn on the map (map frame) and the true one fitted onto it
  (:func:`slamtrials.report.alignment.align_truth`);
* termination reasons and explored fraction of the runs;
* what the runs cost: CPU time and peak memory of the SLAM algorithm and of the whole run, and the time
  per SLAM update, per run and per world (:class:`slamtrials.cost.RunCost`; also in Table I);
* how fast the runs explored: every run's coverage curve per world, the time and distance to 90 % and 99 %
  coverage and how the runs ended (:mod:`slamtrials.report.exploration`);
* how well the final maps draw the floor plans: per world, the mean occupied-cell precision and recall
  within 1 and 2 cells, free-space IoU and ghost area, with their definitions
  (:mod:`slamtrials.report.map_quality`);
* every run (seed, status, errors, outlier marks), and the provenance: config, root seed, versions.

A campaign that is still running, has failed or capped worlds, or no finished run yet still gives a page,
with notes saying what is missing. Every file is written atomically; figures of an earlier report that
are not drawn again are removed.

:func:`compare_report` compares two campaigns on their common worlds
(:func:`slamtrials.report.compare.compare_campaigns`: paired tests when one is a replay of the other,
Welch's otherwise; corrected p-values with intervals corrected alike, verdicts, Stouffer's overall test,
the Fig. 6 trap) and writes ``compare.html``, ``comparison.csv`` and its figures.
"""

from __future__ import annotations

import io
import json
import logging
import math
import platform
import re
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from slamtrials.__about__ import __version__, source_revision
from slamtrials.atomicfile import atomic_write_text
from slamtrials.campaign.config import MetricSettings
from slamtrials.campaign.differences import campaign_differences
from slamtrials.campaign.events import REPLAY_NOTE
from slamtrials.errors import ConfigError, SlamtrialsError
from slamtrials.io.layout import RunFolder
from slamtrials.record import Trajectory
from slamtrials.report import campaign_figures as cf
from slamtrials.report import cost_figures as costf
from slamtrials.report import html as h
from slamtrials.report.compare import (
    A_BETTER,
    B_BETTER,
    Comparison,
    Correction,
    compare_campaigns,
    comparison_notes,
    world_pair_traps,
)
from slamtrials.report.exploration import exploration_section
from slamtrials.report.load import CampaignData, load_campaign
from slamtrials.report.map_quality import map_quality_section
from slamtrials.report.pairing import detect_pairing
from slamtrials.report.tables import METRICS, NOISE_SHARE_LIMIT, OUTLIER_IQR, paper_table, share_percent

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

log = logging.getLogger(__name__)

REPORT_DIR = "report"
REPORT_PAGE = "index.html"
COMPARE_PAGE = "compare.html"
COMPARE_CSV = "comparison.csv"
FIGURES_DIR = "figures"
#: Samplings of the relation-sampling check (the paper's Fig. 3 uses 200).
DEFAULT_REPEATS = 200
UNITS = {"eps_t": "m", "eps_r": "rad"}
SYMBOLS = {"eps_t": "\u03b5t", "eps_r": "\u03b5r"}


# ---------------------------------------------------------------------------------------------- helpers


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", str(name)).strip(".") or "x"


class _FigureWriter:
    """Saves figures as ``<out>/figures/<prefix><name>.png|pdf`` and removes its own stale ones at the end."""

    def __init__(self, out: Path, prefix: str, pdf: bool = True):
        self.out = out
        self.folder = out / FIGURES_DIR
        self.prefix = prefix
        self.pdf = pdf
        self.written: list[Path] = []

    def new(self, width: float, height: float):
        from matplotlib.figure import Figure

        return Figure(figsize=(width, height), dpi=100, layout="constrained")

    def save(self, fig, name: str, caption: str, *, id: str | None = None, alt: str | None = None) -> str:
        base = self.folder / f"{self.prefix}{_safe(name)}"
        engine = fig.get_layout_engine()
        if engine is not None:  # lay out once, not once per file format
            engine.execute(fig)
            fig.set_layout_engine("none")
        if self.pdf:
            paths = cf.save_figure(fig, base, dpi=100)
        else:
            from slamtrials.atomicfile import atomic_write

            paths = [
                atomic_write(
                    base.with_name(base.name + ".png"), lambda handle: fig.savefig(handle, format="png", dpi=100)
                )
            ]
        self.written.extend(paths)
        png, pdf = paths[0], (paths[1] if len(paths) > 1 else None)
        rel = lambda p: p.relative_to(self.out).as_posix()  # noqa: E731
        return h.figure(rel(png), caption, alt=alt, pdf=rel(pdf) if pdf else None, id=id)

    def clean(self) -> None:
        keep = set(self.written)
        if self.folder.is_dir():
            for path in self.folder.glob(f"{self.prefix}*"):
                if path.suffix in (".png", ".pdf") and path not in keep:
                    path.unlink(missing_ok=True)


def parse_run(spec: str | tuple[str, int]) -> tuple[str, int]:
    """``"WORLD/IDX"`` (or ``(world, idx)``) as ``(world, idx)``.

    Raises
    ------
    ConfigError
        Not of that form.
    """
    if isinstance(spec, tuple):
        world, index = spec
        return str(world), int(index)
    world, sep, index = str(spec).rpartition("/")
    if not sep or not world or not index.strip().isdigit():
        raise ConfigError(f"run must be given as WORLD/INDEX (e.g. office_small_01/0), got {spec!r}")
    return world, int(index)


def _finished(data: CampaignData) -> pd.DataFrame:
    done = data.done
    return done[np.isfinite(done["eps_t"]) & np.isfinite(done["eps_r"])].reset_index(drop=True)


def _num(value: Any, digits: int = 3) -> h.Cell:
    return h.Cell(h.fmt_number(value, digits), numeric=True)


def _seconds(value: Any) -> h.Cell:
    """A time in seconds, rounded: one decimal below 10 s, whole seconds above."""
    return h.Cell(h.fmt_seconds(value), numeric=True)


def _amount(value: Any) -> h.Cell:
    """A cost figure (s, ms or MiB), rounded as :func:`~slamtrials.report.html.fmt_seconds` rounds seconds;
    ``-`` where not measured."""
    return h.Cell(h.fmt_seconds(value), numeric=True)


def _share(value: Any) -> h.Cell:
    """The metric's share of the between-run variance as a percentage; ``n/a`` when it is not known."""
    if value is None or not math.isfinite(float(value)):
        return h.Cell("n/a", numeric=True, title="no standard errors recorded for these runs, or fewer than 2 runs")
    return h.Cell(share_percent(float(value)), numeric=True)


def _table_order(data: CampaignData, done: pd.DataFrame) -> list[str]:
    """The worlds that have finished runs, in the order of Table I (the campaign's order): every figure uses it."""
    present = set(done["world"].astype(str))
    return [str(w) for w in data.worlds["world"] if str(w) in present]


def _versions() -> dict[str, str]:
    import matplotlib
    import scipy

    revision = source_revision()
    source = {"source": revision} if revision else {}
    return {
        "slamtrials": __version__,
        **source,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
        "matplotlib": matplotlib.__version__,
    }


def _read_record(data: CampaignData, world: str, run: int):
    from slamtrials.io.runfolder import read_run

    return read_run(data.run_folder(world, run))


def _notes(data: CampaignData, done: pd.DataFrame) -> list[str]:
    notes = []
    if data.kind == "replay":
        notes.append(f"This campaign is a replay of {data.config.get('replay_of')}: {REPLAY_NOTE}.")
    if done.empty:
        notes.append("No run has finished yet: the tables and figures appear as runs finish (rebuild the report).")
    for _, w in data.worlds.iterrows():
        note = f" ({w['note']})" if isinstance(w["note"], str) and w["note"] else ""
        if w["status"] == "capped":
            notes.append(
                f"{w['world']}: stopped at the cap of {w['runs_done']} runs; the run-count rule asked for "
                f"{w['runs_needed']}, so its margins of error are not reached."
            )
        elif w["status"] == "failed":
            notes.append(f"{w['world']}: failed{note}; resume the campaign to retry.")
        elif w["status"] == "short":
            notes.append(f"{w['world']}: short of runs{note}.")
        elif w["status"] in ("running", "pending"):
            notes.append(f"{w['world']}: {w['status']} ({w['runs_done']} runs done so far); this report is a snapshot.")
    failed = data.runs[data.runs["status"] == "failed"]
    if len(failed):
        notes.append(f"{len(failed)} run(s) failed; their errors are listed in the runs table.")
    return notes


# ---------------------------------------------------------------------------------------------- sections


def _overview(data: CampaignData, done: pd.DataFrame) -> str:
    config = data.config
    slam = config.get("slam", {})
    runs = config.get("runs", {})
    counts = data.runs["status"].value_counts()
    items = [
        ("campaign folder", str(data.folder)),
        ("kind", data.kind + (f" of {config.get('replay_of')}" if config.get("replay_of") else "")),
        ("SLAM algorithm", _slam_text(slam)),
        ("simulated sensors", _profile_text(config.get("sim", {}))),
        ("relations per run", _relations_text(config.get("metric", {}))),
        (
            "worlds",
            f"{len(data.worlds)}: "
            + ", ".join(f"{w} {s}" for w, s in zip(data.worlds["world"], data.worlds["status"])),
        ),
        ("runs", ", ".join(f"{int(counts.get(s, 0))} {s}" for s in ("done", "running", "pending", "failed"))),
        (
            "run-count rule",
            f"first {runs.get('initial')} runs, cap {runs.get('max_runs')}, margins \u00b1{runs.get('margin_t')} m "
            f"and \u00b1{runs.get('margin_r')} rad at {_pct(runs.get('confidence'))} confidence ({runs.get('distribution')} quantile)",
        ),
        *([("run times", _run_times(done))] if len(done) else []),
        ("root seed", str(config.get("seed"))),
        ("created", str(data.meta.get("created"))),
    ]
    return h.section("Overview", h.definition_list(items), h.notes(_notes(data, done), id="notes"), id="overview")


def _slam_text(slam: dict) -> str:
    """The provenance line of the SLAM settings: an algorithm with its preset and parameters, or a program."""
    program = slam.get("program")
    if program:
        return (
            f"{slam.get('algorithm')}: external program, offline (command {program.get('command')!r}, input "
            f"{program.get('input')}, output {program.get('output')}, timeout {program.get('timeout')} s)"
        )
    return f"{slam.get('algorithm')} (preset {slam.get('preset')}, params {slam.get('params') or {}})"


def _profile_text(sim: dict[str, Any]) -> str:
    """The error profile the runs were simulated with, and whether the config overrode it: ``error profile
    realistic + 2 overrides (laser.dropout_rate 0.01 instead of 0.02526, ...)``, then where the profile's
    values come from. A stored config that names none is ``paper`` (versions before profiles)."""
    from pydantic import ValidationError

    from slamtrials.campaign.config import stored_sim_config

    sim = sim if isinstance(sim, dict) else {}
    profile = sim.get("profile", "paper")
    name = profile.get("name", "?") if isinstance(profile, dict) else str(profile)
    try:
        config = stored_sim_config(sim)
    except ValidationError:  # a profile this version does not know: its name as stored
        return f"error profile {name}"
    label, overrides = config.profile_label, config.profile_overrides
    changed = ", ".join(f"{o.key} {_value_text(o.value)} instead of {_value_text(o.profile_value)}" for o in overrides)
    text = f"error profile {label}" + (f" ({changed})" if changed else "")
    if name == "paper":
        return text + ": the IROS 2018 Stage set-up (noise-free laser, per-run odometry scale bias)"
    description = config.error_profile.description
    return text + (f": {description}" if description else "")


def _value_text(value: Any) -> str:
    """A field's value, short: ``0.01``, ``[-0.01, 0.01]``."""
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_value_text(v) for v in value) + "]"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def _relations_text(metric: dict[str, Any]) -> str:
    """The relation rule and which SLAM estimate the run errors score."""
    settings = MetricSettings.of_stored(metric)
    which = "the final SLAM estimate" if settings.estimate == "final" else "the online SLAM estimate"
    return f"{settings.sampling.describe()}; the run errors score {which}"


def _run_times(done: pd.DataFrame) -> str:
    """The finished runs' simulated and wall-clock time, in all and per run, rounded."""
    simulated, wall = done["duration_s"].dropna(), done["wall_s"].dropna()
    parts = []
    if len(simulated):
        parts.append(f"{h.fmt_duration(simulated.sum())} simulated (mean {h.fmt_duration(simulated.mean())} per run)")
    if len(wall):
        parts.append(f"{h.fmt_duration(wall.sum())} of worker time (mean {h.fmt_duration(wall.mean())} per run)")
    return "; ".join(parts) or "-"


def _pct(value: Any) -> str:
    try:
        return f"{100 * float(value):g} %"
    except (TypeError, ValueError):
        return "?"


def _table_one(data: CampaignData, done: pd.DataFrame) -> str:
    header = [
        "world",
        "status",
        "runs",
        *(["mean", "std", "\u00b1 CI", "metric share"] * 2),
        "outliers",
        "min \u2013 max " + SYMBOLS["eps_t"] + " (m)",
        "CPU s",
        "ms / update",
        "MiB",
        "runs ended by",
        "note",
    ]
    groups = [
        ("", 3),
        (f"{SYMBOLS['eps_t']} (m)", 4),
        (f"{SYMBOLS['eps_r']} (rad)", 4),
        ("", 2),
        ("SLAM cost per run", 3),
        ("", 2),
    ]
    rows, classes = [], []
    reasons = done.groupby("world")["termination"].agg(lambda s: Counter(s.fillna("unknown"))) if len(done) else {}
    for _, w in data.worlds.iterrows():
        needed = w["runs_needed"]
        runs = f"{w['runs_done']}" + (f" / {needed}" if pd.notna(needed) and int(needed) > w["runs_done"] else "")
        if w["capped"] and pd.notna(w["runs_target"]):
            runs += f" (capped at {w['runs_target']})"
        cells = [w["world"], w["status"], h.Cell(runs, numeric=True)]
        for metric, digits in (("eps_t", 3), ("eps_r", 4)):
            cells += [
                _num(w[f"{metric}_mean"], digits),
                _num(w[f"{metric}_std"], digits),
                _num(w[f"{metric}_half_width"], digits),
                _share(w[f"{metric}_metric_share"]) if w["runs_done"] else h.Cell("-", numeric=True),
            ]
        cells.append(
            h.Cell(
                f"{w['eps_t_outliers']} / {w['eps_r_outliers']}" if w["runs_done"] else "-",
                numeric=True,
                title=f"{SYMBOLS['eps_t']} / {SYMBOLS['eps_r']} outliers beyond 1.5 IQR",
            )
        )
        cells.append(
            h.Cell(
                f"{h.fmt_number(w['eps_t_min'])} \u2013 {h.fmt_number(w['eps_t_max'])}" if w["runs_done"] else "-",
                numeric=True,
            )
        )
        cells += [
            _amount(w["slam_cpu_s_mean"]),
            h.Cell(
                _update_text(w["update_ms_median_mean"], w["update_ms_p90_mean"]),
                numeric=True,
                title="median / 90th percentile of the time per SLAM update (ms), mean over the runs",
            ),
            _amount(w["slam_peak_mib_mean"]),
        ]
        counter = reasons.get(w["world"], {}) if len(done) else {}
        cells.append(", ".join(f"{k} {v}" for k, v in sorted(counter.items())))
        cells.append(w["note"] if isinstance(w["note"], str) else "")
        rows.append(cells)
        classes.append({"failed": "bad", "capped": "warn", "short": "warn", "done": None}.get(w["status"], "warn"))
    confidence = data.confidence
    caption = (
        f"The paper's Table I: per world, the mean and sample standard deviation (divisor n \u2212 1) of the runs' "
        f"translational error {SYMBOLS['eps_t']} (m) and rotational error {SYMBOLS['eps_r']} (rad), and the half width "
        f"of the {_pct(confidence)} confidence interval of the mean. Runs: done (/ needed by the run-count rule when more, "
        f"also where the cap stopped a world). SLAM cost per run: the mean over the runs of the SLAM algorithm's CPU "
        f"time (s), of its time per update (ms, median / 90th percentile) and of its peak memory (MiB), as the "
        f"section on cost defines them; - where not measured."
    )
    parts = [  # the caption above, as wide as the page: the table scrolls sideways when it is wider
        f'<p class="explain" id="summary-caption">{h.esc(caption)}</p>',
        '<div style="overflow-x:auto">'
        + h.table(header, rows, id="summary-table", row_classes=classes, groups=groups)
        + "</div>",
        _share_note(data),
        _outlier_note(data),
    ]
    if len(done):
        summary = data.worlds[data.worlds["runs_done"] > 0]
        for metric, unit in (("eps_t", "m"), ("eps_r", "rad")):
            printed = paper_table(summary, metric, population=True)
            rows = [
                [label, *[_num(v, 3 if metric == "eps_t" else 4) for v in printed.loc[label]]]
                for label in printed.index
            ]
            parts.append(
                '<div style="overflow-x:auto">'
                + h.table(
                    ["", *printed.columns],
                    rows,
                    id=f"paper-table-{metric}",
                    caption=f"As printed in the paper: {SYMBOLS[metric]} ({unit}) per world, std dev with divisor n (Definition III.3).",
                )
                + "</div>"
            )
    return h.section("Table I: localization error per world", *parts, id="table-1")


def _update_text(median: Any, p90: Any) -> str:
    """``median / p90`` of the time per update (ms), ``-`` where not measured."""
    if not (isinstance(median, (int, float)) and math.isfinite(median)):
        return "-"
    return f"{h.fmt_seconds(median)} / {h.fmt_seconds(p90)}"


def _share_note(data: CampaignData) -> str:
    """The paragraph under Table I that says what the metric-share columns are, and which worlds exceed 10 %."""
    limit = _pct(NOISE_SHARE_LIMIT)
    text = (
        "Metric share: each run's error is the mean over its sampled relations, so it carries a standard error "
        "se of its own (the per-relation errors' standard deviation over \u221aN). Over a world's runs, the "
        "variance of the run errors is the variance between the runs plus, on average, se\u00b2; the metric "
        "share is mean(se\u00b2) over the variance of the run errors (sample variance): the part of the "
        f"run-to-run spread that is the metric's own sampling noise. Below {limit}, the differences between "
        "the runs are real (the algorithm's, not the metric's), and so are the standard deviation, the best "
        "and worst runs and the outliers; near 100 % the runs cannot be told apart. n/a: the runs have no "
        "standard error recorded (scored by an earlier version of slamtrials) or there are fewer than 2."
    )
    high = []
    for _, w in data.worlds.iterrows():
        shares = [
            f"{SYMBOLS[metric]} {100 * w[f'{metric}_metric_share']:.0f} %"
            for metric in METRICS
            if math.isfinite(w[f"{metric}_metric_share"]) and w[f"{metric}_metric_share"] >= NOISE_SHARE_LIMIT
        ]
        if shares:
            high.append(f"{w['world']} ({', '.join(shares)})")
    if high:
        text += f" At or above {limit} here: " + ", ".join(high) + "."
    return f'<p class="explain" id="metric-share-note">{h.esc(text)}</p>'


def _outlier_note(data: CampaignData) -> str:
    """The paragraph under Table I that says how the outlier column is counted."""
    text = (
        f"Outliers: how many of the world's finished runs lie beyond Tukey's fences, for {SYMBOLS['eps_t']} / "
        f"{SYMBOLS['eps_r']}: more than {OUTLIER_IQR:g} interquartile ranges (IQR = Q3 \u2212 Q1) below the first "
        "quartile Q1 or above the third quartile Q3 of that world's run errors (quartiles by linear "
        "interpolation), the whiskers of Fig. 5's boxes. An outlier is a run unusual among its world's runs, not "
        "a failed one (failed runs have no error); with few runs the quartiles are rough, so an outlier there is "
        "a hint, and where the metric share is high it may be the metric's noise. The runs table at the end marks "
        "each outlier run."
    )
    return f'<p class="explain" id="outlier-note">{h.esc(text)}</p>'


def _fig1(figs: _FigureWriter, data: CampaignData, done: pd.DataFrame) -> str:
    if done.empty:
        return h.section("Fig. 1: run errors per world", "<p>No finished runs.</p>", id="fig-1")
    parts = []
    worlds = _table_order(data, done)
    fig = figs.new(11, 3.8)
    axes = fig.subplots(1, 2)
    for ax, metric in zip(axes, METRICS):
        cf.draw_sorted_errors(ax, done, worlds, metric)
    parts.append(
        figs.save(
            fig,
            "fig1_all",
            "Every world's run errors sorted from largest to smallest (the paper's Fig. 1 "
            "as printed): left translational, right rotational.",
            id="fig-1-all",
        )
    )
    gallery = []
    for i, world in enumerate(worlds):
        n = int((done["world"] == world).sum())
        fig = figs.new(min(4 + 0.18 * n, 14) * 2 / 1.6, 3.4)
        axes = fig.subplots(1, 2)
        for ax, metric in zip(axes, METRICS):
            cf.draw_world_errors(ax, done, world, metric, confidence=data.confidence, distribution=data.distribution)
        gallery.append(
            figs.save(
                fig,
                f"fig1_{i:03d}_{world}",
                f"{world}: its {n} runs' errors, largest first, labelled by run index; the mean and its "
                f"{_pct(data.confidence)} confidence band.",
            )
        )
    parts.append('<div class="gallery">' + "\n".join(gallery) + "</div>")
    return h.section(
        "Fig. 1: run errors per world, largest first",
        *parts,
        id="fig-1",
        intro="The variability of one algorithm in one building: why a single run is not a measurement.",
    )


def _fig5(figs: _FigureWriter, data: CampaignData, done: pd.DataFrame) -> str:
    if done.empty:
        return h.section("Fig. 5: all runs of all worlds", "<p>No finished runs.</p>", id="fig-5")
    worlds = _table_order(data, done)
    fig = figs.new(min(max(7.0, 0.45 * len(worlds) + 3), 30), 7.5)
    axes = fig.subplots(2, 1)
    for ax, metric in zip(axes, METRICS):
        cf.draw_all_runs(ax, done, metric, order=worlds)
    count_t, count_r = int(done["outlier_t"].sum()), int(done["outlier_r"].sum())
    caption = (
        f"The paper's Fig. 5: every run of every world (points), a box per world (quartiles, whiskers at 1.5 IQR), "
        f"the world means (orange), and outliers beyond Tukey's fences (the outlier column of Table I) as red "
        f"crosses: {count_t} in {SYMBOLS['eps_t']} (top), {count_r} in {SYMBOLS['eps_r']} (bottom). Worlds in the "
        "order of Table I."
    )
    return h.section(
        "Fig. 5: all runs of all worlds, outliers marked", figs.save(fig, "fig5_all_runs", caption), id="fig-5"
    )


def draw_trap_pair(
    ax,
    low: np.ndarray,
    high: np.ndarray,
    labels: tuple[str, str],
    i_low: int,
    i_high: int,
    metric: str = "eps_t",
    colors: tuple[str, str] = ("tab:blue", "tab:orange"),
) -> None:
    """Two samples side by side (``low``: lower mean) with their means and the most misleading pair ringed.

    The pair ``(low[i_low], high[i_high])`` is the single-run comparison that contradicts the means the
    most (the paper's Fig. 6); it is joined by a dashed line (gid ``"trap"``) when it is reversed.
    ``colors`` are those of ``low`` and ``high`` (a comparison keeps one colour per campaign).
    """
    for x, values, color in ((0, low, colors[0]), (1, high, colors[1])):
        offsets = ((np.arange(len(values)) * cf.GOLDEN) % 1.0 - 0.5) * 0.35
        ax.plot(x + offsets, values, "o", ms=4, color=color, alpha=0.75)
        ax.plot([x - 0.3, x + 0.3], [values.mean()] * 2, color=color, lw=2.5, gid=f"mean:{x}")
    if low[i_low] > high[i_high]:
        ax.plot([0, 1], [low[i_low], high[i_high]], "k--", lw=1, gid="trap")
        ax.plot([0, 1], [low[i_low], high[i_high]], "o", ms=11, mfc="none", mec="red", mew=1.8)
    ax.set_xticks([0, 1], labels=list(labels), fontsize=8)
    ax.set_xlim(-0.6, 1.6)
    ax.set_ylabel(cf.METRIC_LABELS[metric], fontsize=8)


def _fig6(figs: _FigureWriter, done: pd.DataFrame) -> str:
    title = "Fig. 6: where single runs mislead"
    if done["world"].nunique() < 2:
        return h.section(title, "<p>Needs finished runs in at least two worlds.</p>", id="fig-6")
    traps = world_pair_traps(done, "eps_t")
    reversed_ = traps[traps["reversed_by"] > 0].sort_values(
        ["means_differ", "reversed_by"], ascending=False, kind="stable"
    )
    intro = (
        "The paper's Fig. 6: for two worlds, one run of each can rank them opposite to their mean errors. "
        "Pairs of worlds where this happens (translational error): first those whose means differ significantly "
        "(Welch, 5 %), then by how much the single runs reverse them."
    )
    if reversed_.empty:
        return h.section(
            title,
            "<p>No pair of worlds has a single-run comparison that contradicts the means.</p>",
            id="fig-6",
            intro=intro,
        )
    rows = []
    for _, r in reversed_.head(15).iterrows():
        rows.append(
            [
                r["world_low"],
                _num(r["mean_low"]),
                r["world_high"],
                _num(r["mean_high"]),
                _num(r["p"], 4),
                "yes" if r["means_differ"] else "no",
                f"#{r['run_low']}: {r['value_low']:.3f} m",
                f"#{r['run_high']}: {r['value_high']:.3f} m",
                h.Cell(f"{r['reversed_fraction']:.0%}", numeric=True),
            ]
        )
    header = [
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
    top = reversed_.iloc[0]
    sentence = (
        f"{top['world_low']} has the lower mean error ({top['mean_low']:.3f} m against {top['mean_high']:.3f} m), "
        f"but its run #{top['run_low']} ({top['value_low']:.3f} m) is worse than run #{top['run_high']} of "
        f"{top['world_high']} ({top['value_high']:.3f} m): comparing these two single runs gives the opposite verdict; "
        f"{top['reversed_fraction']:.0%} of all pairs of single runs do. The difference of the means is "
        f"{'significant' if top['means_differ'] else 'not significant'} (Welch p = {top['p']:.3g})."
    )
    low = done.loc[done["world"] == top["world_low"], ["run", "eps_t"]]
    high = done.loc[done["world"] == top["world_high"], ["run", "eps_t"]]
    fig = figs.new(5.0, 3.6)
    ax = fig.subplots()
    draw_trap_pair(
        ax,
        low["eps_t"].to_numpy(),
        high["eps_t"].to_numpy(),
        (top["world_low"], top["world_high"]),
        int(np.flatnonzero(low["run"].to_numpy() == top["run_low"])[0]),
        int(np.flatnonzero(high["run"].to_numpy() == top["run_high"])[0]),
    )
    picture = figs.save(
        fig,
        "fig6_trap",
        f"The runs of {top['world_low']} and {top['world_high']} with their means; "
        "ringed and joined: the single-run pair that contradicts the means the most.",
    )
    return h.section(
        title, f"<p>{h.esc(sentence)}</p>", picture, h.table(header, rows, id="trap-table"), id="fig-6", intro=intro
    )


def _choose_sampling_run(data: CampaignData, done: pd.DataFrame, sampling_run) -> tuple[str, int] | None:
    if sampling_run is not None:
        world, index = parse_run(sampling_run)
        rows = data.runs[(data.runs["world"] == world) & (data.runs["run"] == index)]
        if rows.empty:
            raise ConfigError(f"{data.folder}: has no run {world}/{index} (worlds: {', '.join(data.worlds['world'])})")
        if rows["status"].iloc[0] != "done":
            raise ConfigError(f"{data.folder}: run {world}/{index} is not finished (status {rows['status'].iloc[0]})")
        return world, index
    for world in data.worlds["world"]:
        mine = done[done["world"] == world]
        if len(mine):
            return world, int(mine["run"].min())
    return None


def _fig3(
    figs: _FigureWriter, data: CampaignData, done: pd.DataFrame, chosen: tuple[str, int] | None, repeats: int, seed: int
) -> str:
    title = "Fig. 3: the relation-sampling check"
    if chosen is None:
        return h.section(title, "<p>No finished run to check.</p>", id="fig-3")
    world, index = chosen
    metric = MetricSettings.of_stored(data.config.get("metric", {}))
    try:
        record = _read_record(data, world, index)
        if record.estimate is None:
            raise SlamtrialsError("the run folder holds no SLAM estimate")
        truth = Trajectory(t=record.t, poses=record.truth)
        estimate = Trajectory(t=record.t, poses=np.asarray(record.estimate, dtype=np.float64))
        odometry = Trajectory(t=record.t, poses=record.odometry)
        sequence = np.random.SeedSequence(int(seed))
        means = {
            component: cf.repeated_sampling_means(
                truth,
                estimate,
                repeats,
                sequence,
                component=component,
                rule=metric.sampling,
                tolerance=metric.tolerance,
                odometry=odometry,
            )
            for component in ("translational", "rotational")
        }
    except SlamtrialsError as exc:
        log.warning("relation-sampling check of %s/%d: %s", world, index, exc)
        return h.section(title, h.notes([f"Run {world}/{index} could not be checked: {exc}"]), id="fig-3")
    row = done[(done["world"] == world) & (done["run"] == index)].iloc[0]
    margins = dict(zip(METRICS, metric.sampling.margins(float(row["eps_t"]), float(row["eps_r"]))))
    fig = figs.new(11, 3.8)
    axes = fig.subplots(1, 2)
    for ax, (component, values), metric_name in zip(axes, means.items(), METRICS):
        unit = UNITS[metric_name]
        with warnings.catch_warnings():  # a run whose relations all have the same error: no spread to test
            warnings.filterwarnings("ignore", message=".*range zero.*", category=UserWarning)
            cf.draw_sampling_check(ax, values, xlabel=f"mean {component} error of one sampling ({unit})")
        ax.axvline(float(row[metric_name]), color="black", ls=":", lw=1.2, gid="campaign_value")
        ax.set_title(f"{world} run #{index}: {SYMBOLS[metric_name]} over {repeats} samplings", fontsize=9)
    caption = (
        f"The paper's Fig. 3 for run #{index} of {world}: the distribution of the run's mean error over {repeats} "
        f"independent samplings of relations (each by the campaign's {metric.sampling.describe()}), "
        f"with a fitted normal; dotted: the value the campaign recorded "
        f"({row['eps_t']:.4f} m, {row['eps_r']:.4f} rad). Sampling seed {seed}."
    )
    spread = [
        f"{SYMBOLS[m]}: mean {v.mean():.4g}, sd {v.std(ddof=1):.2g} over samplings (margin \u00b1{margins[m]:.2g})"
        for m, v in zip(METRICS, means.values())
    ]
    return h.section(
        title,
        figs.save(fig, "fig3_sampling", caption),
        "<p>" + h.esc("; ".join(spread)) + "</p>",
        id="fig-3",
        intro="Is the sampled mean of one run approximately normal with a spread within the margin of error?",
    )


#: Width (inches, at 100 dpi) of a figure shown at the page's full width (its max-width is 1250 px).
PAGE_WIDTH_IN = 12.0


def _fig4_panel(ax, record, label: str, row: pd.Series):
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


def _fig4(figs: _FigureWriter, data: CampaignData, done: pd.DataFrame) -> str:
    title = "Fig. 4: best and worst map of every world"
    if done.empty:
        return h.section(title, "<p>No finished runs.</p>", id="fig-4")
    pictures, problems = [], []
    for i, world in enumerate(_table_order(data, done)):
        mine = done[done["world"] == world]  # in run order: a tie goes to the lower run index
        best, worst = mine.loc[mine["eps_t"].idxmin()], mine.loc[mine["eps_t"].idxmax()]
        picks = [("best", best)] if best["run"] == worst["run"] else [("best", best), ("worst", worst)]
        width = PAGE_WIDTH_IN if len(picks) == 2 else PAGE_WIDTH_IN / 2
        fig = figs.new(width, 6.0)
        axes = np.atleast_1d(fig.subplots(1, len(picks)))
        fits = []
        try:
            for ax, (label, row) in zip(axes, picks):
                fits.append(_fig4_panel(ax, _read_record(data, world, int(row["run"])), label, row))
        except SlamtrialsError as exc:
            problems.append(f"{world}: a run folder could not be read ({exc})")
            log.warning("Fig. 4 of %s: %s", world, exc)
            continue
        handles, labels = axes[0].get_legend_handles_labels()
        if handles:
            fig.legend(handles, labels, loc="outside lower center", ncols=len(handles), fontsize=10, frameon=False)
        # the panels' height follows the maps' shape, so a wide or a tall building fills the page's width
        x0, x1 = axes[0].get_xlim()
        y0, y1 = axes[0].get_ylim()
        aspect = (y1 - y0) / (x1 - x0) if x1 > x0 else 1.0
        fig.set_size_inches(width, float(np.clip((width / len(picks) - 0.9) * aspect + 1.5, 3.5, 11.0)))
        described = " and ".join(
            f"the {label} run #{int(row['run'])} ({SYMBOLS['eps_t']} {row['eps_t']:.3f} m"
            + (f" over {int(row['relations']):,} relations" if pd.notna(row["relations"]) else "")
            + f", {SYMBOLS['eps_r']} {row['eps_r']:.4f} rad)"
            for label, row in picks
        )
        residuals = [f"{fit.rms:.3f} m" for fit in fits if fit is not None]
        methods = {fit.method for fit in fits if fit is not None}
        how = (
            "moved into the map frame through the first poses (the truth does not move)"
            if methods == {"first pose"}
            else "moved into the map frame by a least-squares SE(2) fit (rotation and translation, no scale) of "
            "the true positions onto the estimated ones"
        )
        caption = (
            f"{world}: the final SLAM map of {described}, the lowest and highest {SYMBOLS['eps_t']} of its "
            f"{len(mine)} runs. On each map, in the map frame: the SLAM estimate as recorded (red; dot: its "
            f"start) and the ground truth (wide, blue) {how}"
            + (
                f"; after the fit the true positions lie {' and '.join(residuals)} (rms) from the estimate."
                if residuals
                else "."
            )
        )
        pictures.append(figs.save(fig, f"fig4_{i:03d}_{world}", caption, id=f"fig-4-{_safe(world)}"))
    return h.section(
        title,
        h.notes(problems),
        *pictures,
        id="fig-4",
        intro="The metric should tell a good map from a bad one (the paper's Fig. 4): per world, in the order of "
        "Table I, the map and trajectories of the run with the smallest and the largest translational error "
        f"{SYMBOLS['eps_t']} (as the catalog records it).",
    )


def _termination(figs: _FigureWriter, data: CampaignData, done: pd.DataFrame) -> str:
    title = "How the runs ended: termination reasons and explored fraction"
    if done.empty:
        return h.section(title, "<p>No finished runs.</p>", id="termination")
    mapped = done[np.isfinite(done["mapped"])]
    fig = figs.new(min(max(10.0, 0.6 * done["world"].nunique() + 4), 30), 4.0)
    axes = fig.subplots(1, 2 if len(mapped) else 1, squeeze=False)[0]
    worlds = _table_order(data, done)
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
                _num(mine["mapped"].mean(), 3),
                _num(mine["mapped"].min(), 3),
                _seconds(mine["duration_s"].mean()),
                _seconds(mine["wall_s"].mean()),
            ]
        )
    table = h.table(
        ["world", "runs", "ended by", "explored (mean)", "explored (min)", "simulated s (mean)", "wall s (mean)"],
        rows,
        id="termination-table",
    )
    return h.section(title, picture, table, id="termination")


#: What each cost figure is, as the cost section explains it (:class:`slamtrials.cost.RunCost`).
_COST_TEXT = (
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


def _cost(figs: _FigureWriter, data: CampaignData, done: pd.DataFrame) -> str:
    title = "What the runs cost: CPU time and memory"
    explain = f'<p class="explain" id="cost-note">{h.esc(_COST_TEXT)}</p>'
    measured = done[np.isfinite(costf.cost_values(done, "slam_cpu_s"))] if len(done) else done
    if measured.empty:
        return h.section(title, explain, "<p>No finished run recorded its cost.</p>", id="cost")
    worlds = _table_order(data, done)
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
    rows = []
    for world in worlds:
        mine = done[done["world"] == world]
        slam_cpu, run_cpu = costf.cost_values(mine, "slam_cpu_s"), costf.cost_values(mine, "run_cpu_s")
        both = np.isfinite(slam_cpu) & np.isfinite(run_cpu) & (run_cpu > 0)
        rows.append(
            [
                world,
                h.Cell(str(int(np.isfinite(slam_cpu).sum())), numeric=True),
                *[
                    _amount(_mean(costf.cost_values(mine, name)))
                    for name in ("slam_cpu_s", "run_cpu_s", "update_ms_median", "update_ms_p90")
                ],
                h.Cell(
                    f"{100 * slam_cpu[both].sum() / run_cpu[both].sum():.0f} %" if both.any() else "-", numeric=True
                ),
                *[_amount(_mean(costf.cost_values(mine, name))) for name in ("slam_peak_mib", "run_peak_mib")],
            ]
        )
    table = h.table(
        [
            "world",
            "runs measured",
            "SLAM CPU s",
            "run CPU s",
            "ms per update (median)",
            "ms per update (p90)",
            "SLAM share of the CPU",
            "SLAM MiB",
            "run MiB",
        ],
        rows,
        id="cost-table",
        caption="Means over the world's runs; SLAM share of the CPU: the runs' SLAM CPU time over their whole CPU time.",
    )
    return h.section(title, explain, picture, table, id="cost")


def _mean(values: np.ndarray) -> float:
    """The mean of the finite values, NaN for none."""
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if len(finite) else math.nan


def _runs_table(data: CampaignData) -> str:
    runs = data.runs
    rows, classes = [], []
    for _, r in runs.iterrows():
        flag = ", ".join(n for n, c in (("\u03b5t", r["outlier_t"]), ("\u03b5r", r["outlier_r"])) if c)
        rows.append(
            [
                r["world"],
                h.Cell(str(r["run"]), numeric=True),
                h.Cell(str(r["seed"]), numeric=True),
                r["status"],
                _num(r["eps_t"], 4),
                _num(r["eps_r"], 4),
                flag,
                r["termination"] if isinstance(r["termination"], str) else "",
                _num(r["mapped"], 3),
                _seconds(r["duration_s"]),
                _seconds(r["wall_s"]),
                _amount(r.get("slam_cpu_s")),
                _amount(r.get("update_ms_median")),
                _amount(r.get("slam_peak_mib")),
                r["error"] if isinstance(r["error"], str) else "",
            ]
        )
        classes.append("bad" if r["status"] == "failed" else ("warn" if flag else None))
    table = h.table(
        [
            "world",
            "run",
            "seed",
            "status",
            "\u03b5t (m)",
            "\u03b5r (rad)",
            "outlier in",
            "ended by",
            "explored",
            "sim s",
            "wall s",
            "SLAM CPU s",
            "ms per update",
            "SLAM MiB",
            "error",
        ],
        rows,
        id="runs-table",
        row_classes=classes,
        caption="outlier in: the errors in which the run lies beyond its world's Tukey fences (see the outlier "
        "column of Table I); sim s: simulated duration; wall s: the run's wall-clock time on its worker; SLAM CPU s, "
        "ms per update (median) and SLAM MiB: what the run cost (see the section on cost).",
    )
    return h.section(
        "Every run",
        f"<details><summary>{len(runs)} runs with their seeds, errors and outlier marks</summary>{table}</details>",
        id="runs",
    )


def _provenance(data: CampaignData) -> str:
    import yaml

    config_text = yaml.safe_dump(data.config, sort_keys=False, default_flow_style=None, width=110)
    seen: Counter = Counter()
    for folder in data.done["folder"]:
        path = RunFolder(data.folder / str(folder)).run_json
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        versions = doc.get("versions")
        if isinstance(versions, dict):
            seen[json.dumps(versions, sort_keys=True)] += 1
    run_versions = [
        [", ".join(f"{k} {v}" for k, v in json.loads(key).items()), count] for key, count in seen.most_common()
    ]
    meta = [(k, v) for k, v in sorted(data.meta.items())]
    return h.section(
        "Provenance",
        "<h3>Campaign catalog</h3>",
        h.definition_list(
            [
                *meta,
                ("root seed", data.config.get("seed")),
                (
                    "run seeds",
                    "each (world, run index) has its own stream from numpy.random.SeedSequence of "
                    "the root seed (listed per run in the runs table)",
                ),
            ]
        ),
        "<h3>Versions of the runs (from run.json)</h3>",
        h.table(["versions", "runs"], run_versions, id="versions-table")
        if run_versions
        else "<p>No run folder read.</p>",
        "<h3>This report</h3>",
        h.definition_list(sorted(_versions().items())),
        "<h3>Configuration</h3>",
        h.pre(config_text, id="config"),
        id="provenance",
    )


# ---------------------------------------------------------------------------------------------- public


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
    data = load_campaign(campaign_path)
    done = _finished(data)
    chosen = _choose_sampling_run(data, done, sampling_run)  # a bad --run fails before anything is written
    out = Path(out_dir) if out_dir is not None else data.folder / REPORT_DIR
    out.mkdir(parents=True, exist_ok=True)
    figs = _FigureWriter(out, "report_", pdf)
    title = f"{data.kind.capitalize()} report: {data.folder.name}"
    slam = data.config.get("slam", {})
    subtitle = (
        f"SLAM algorithm {slam.get('algorithm')}; {len(data.worlds)} worlds, {len(done)} finished runs; "
        f"errors of the Kuemmerle et al. metric on sampled relations (Amigoni, Castelli, Luperto, IROS 2018)."
    )
    body = [
        _overview(data, done),
        _table_one(data, done),
        _fig1(figs, data, done),
        _fig5(figs, data, done),
        _fig6(figs, done),
        _fig3(figs, data, done, chosen, repeats, seed),
        _fig4(figs, data, done),
        _termination(figs, data, done),
        _cost(figs, data, done),
        exploration_section(figs, data, done, _table_order(data, done)),
        map_quality_section(done, _table_order(data, done)),
        _runs_table(data),
        _provenance(data),
    ]
    nav = [
        ("overview", "Overview"),
        ("table-1", "Table I"),
        ("fig-1", "Fig. 1"),
        ("fig-5", "Fig. 5"),
        ("fig-6", "Fig. 6"),
        ("fig-3", "Fig. 3"),
        ("fig-4", "Fig. 4"),
        ("termination", "Termination"),
        ("cost", "Cost"),
        ("exploration", "Exploration"),
        ("map-quality", "Map quality"),
        ("runs", "Runs"),
        ("provenance", "Provenance"),
    ]
    page = atomic_write_text(out / REPORT_PAGE, h.page(title, body, subtitle=subtitle, nav=nav))
    figs.clean()
    return page


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


def _labels(a: CampaignData, b: CampaignData) -> tuple[str, str]:
    names = (a.folder.name, b.folder.name)
    return names if names[0] != names[1] else ("A", "B")


def _compare_notes(a: CampaignData, b: CampaignData, comparison: Comparison, unpaired_because: str = "") -> list[str]:
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


def _interval(low: float, high: float, digits: int) -> h.Cell:
    return h.Cell(f"[{h.fmt_number(low, digits)}, {h.fmt_number(high, digits)}]", numeric=True)


def _comparison_table(comparison: Comparison, metric: str) -> str:
    rows, classes = [], []
    unit = UNITS[metric]
    digits = 3 if metric == "eps_t" else 4
    paired = comparison.paired
    level = comparison.intervals[metric]
    for _, r in comparison.for_metric(metric).iterrows():
        cells = [
            r["world"],
            *([h.Cell(str(r["n_a"]), numeric=True)] if paired else []),
            *([] if paired else [h.Cell(str(r["n_a"]), numeric=True), h.Cell(str(r["n_b"]), numeric=True)]),
            _num(r["mean_a"], digits),
            _num(r["mean_b"], digits),
            _num(r["difference"], digits),
            _interval(r["ci_adj_low"], r["ci_adj_high"], digits),
            _interval(r["ci_low"], r["ci_high"], digits),
            _num(r["p"], 4),
            _num(r["p_adjusted"], 4),
            *([_num(r["wilcoxon_p_adjusted"], 4)] if paired else []),
            *([_num(r["correlation"], 2)] if paired else []),
            r["verdict"],
            h.Cell(
                h.fmt_number(r["trap_fraction"] * 100, 0) + " %" if math.isfinite(r["trap_fraction"]) else "-",
                numeric=True,
            ),
        ]
        rows.append(cells)
        classes.append("good" if r["verdict"] == B_BETTER else ("bad" if r["verdict"] == A_BETTER else None))
    name_a, name_b = comparison.labels
    test = "paired t" if paired else "Welch"
    header = [
        "world",
        *(["pairs"] if paired else [f"n {name_a}", f"n {name_b}"]),
        f"mean {name_a}",
        f"mean {name_b}",
        f"{name_b} \u2212 {name_a}",
        f"CI: {level.label}",
        f"CI: {1 - comparison.alpha:.0%} this world alone (unadjusted)",
        f"p ({test})",
        f"p ({test}, {comparison.correction})",
        *([f"p (Wilcoxon check, {comparison.correction})"] if paired else []),
        *(["r of the paired errors"] if paired else []),
        "verdict",
        "single-run pairs reversed",
    ]
    how = (
        "the paired t-test on the run-by-run differences (runs paired by world and index), with the Wilcoxon "
        "signed-rank test of the same differences as a check"
        if paired
        else "Welch's t-test (the runs of the two campaigns are independent)"
    )
    return h.table(
        header,
        rows,
        id=f"comparison-table-{metric}",
        row_classes=classes,
        caption=f"{SYMBOLS[metric]} ({unit}), lower is better; {comparison.pairing}: per world the difference of "
        f"mean errors by {how}; p-values corrected for {len(rows)} comparisons ({comparison.correction}) and the "
        f"first interval corrected alike ({level.label}); the second holds for one world alone. Verdict on the "
        f"corrected p at \u03b1 = {comparison.alpha:g}."
        + (
            " r: the correlation of a run's errors in the two campaigns; pairing narrows the interval only where it is positive."
            if paired
            else ""
        ),
    )


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
    done_a, done_b = _finished(data_a), _finished(data_b)
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
    figs = _FigureWriter(out, "compare_", pdf)
    name_a, name_b = comparison.labels
    notes = _compare_notes(data_a, data_b, comparison, pairing.note)

    forest = []
    for metric in METRICS:
        rows = comparison.for_metric(metric)
        fig = figs.new(8.5, max(2.8, 0.42 * len(rows) + 1.8))
        cf.draw_comparison(fig.subplots(), comparison, metric)
        forest.append(
            figs.save(
                fig,
                f"forest_{metric}",
                f"{name_b} \u2212 {name_a} in mean {SYMBOLS[metric]} per world ({comparison.pairing}) with "
                f"{comparison.intervals[metric].label} intervals, coloured by verdict ({correction} correction); "
                "diamonds: the most misleading single-run pair where it contradicts the means; right margin: share "
                "of run pairs that reverse the means.",
            )
        )
    trap_rows = comparison.for_metric("eps_t")
    trap_rows = (
        trap_rows[np.isfinite(trap_rows["trap_fraction"])]
        .sort_values("trap_fraction", ascending=False, kind="stable")
        .head(12)
    )
    trap_picture = ""
    if len(trap_rows):
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
                draw_trap_pair(ax, vb, va, (name_b, name_a), ib, ia, colors=(color_b, color_a))
            else:
                draw_trap_pair(ax, va, vb, (name_a, name_b), ia, ib, colors=(color_a, color_b))
            ax.set_title(f"{r['world']}: {r['verdict']}\n{r['trap_fraction']:.0%} of run pairs reversed", fontsize=8)
        for ax in axes[len(trap_rows) :]:
            ax.set_visible(False)
        trap_picture = figs.save(
            fig,
            "trap",
            "The paper's Fig. 6 trap between the two campaigns: per world (most reversed "
            "first), the runs of each and their means (A blue, B orange, the lower mean on the "
            "left); ringed and joined: the single-run pair that contradicts the means the most.",
        )
    csv_text = io.StringIO()
    comparison.table.to_csv(csv_text, index=False, lineterminator="\n")
    table_csv = atomic_write_text(out / COMPARE_CSV, csv_text.getvalue())

    def describe(d: CampaignData) -> str:
        return (
            f"{d.folder} ({d.kind}, {d.config.get('slam', {}).get('algorithm')}, "
            f"{int((d.runs['status'] == 'done').sum())} finished runs)"
        )

    differences = campaign_differences(data_a.folder, data_b.folder)
    verdicts = [f"{SYMBOLS[m]}: {comparison.overall[m].statement}" for m in METRICS if m in comparison.overall]
    traps = trap_sentences(comparison)
    body = [
        h.section(
            "Campaigns",
            h.definition_list(
                [
                    (f"A = {name_a}", describe(data_a)),
                    (f"B = {name_b}", describe(data_b)),
                    ("settings that differ (A -> B)", "; ".join(map(str, differences)) or "none"),
                    ("compared worlds", ", ".join(comparison.for_metric(METRICS[0])["world"])),
                    (
                        "test",
                        f"{comparison.pairing}: "
                        + (
                            "paired t-test per world (Wilcoxon signed-rank as a check)"
                            if comparison.paired
                            else "Welch's t-test per world"
                        )
                        + f", {correction} correction across worlds, \u03b1 = {alpha:g}; intervals: "
                        + "; ".join(
                            f"{SYMBOLS[m]} {comparison.intervals[m].label}"
                            for m in METRICS
                            if m in comparison.intervals
                        )
                        + "; overall: "
                        + (comparison.overall[METRICS[0]].test if METRICS[0] in comparison.overall else "-")
                        + " (sign test over worlds as a check)",
                    ),
                ]
            ),
            h.notes(notes, id="notes"),
            id="campaigns",
        ),
        h.section(
            "Overall verdict",
            '<ul id="overall">' + "".join(f"<li>{h.esc(v)}</li>" for v in verdicts) + "</ul>",
            id="verdict",
        ),
        h.section(
            "Per world",
            *(_comparison_table(comparison, m) for m in METRICS),
            f'<p><a href="{COMPARE_CSV}">comparison.csv</a></p>',
            *forest,
            id="per-world",
        ),
        h.section(
            "Fig. 6: where single runs would give the opposite verdict",
            "<ul>" + "".join(f"<li>{h.esc(s)}</li>" for s in traps) + "</ul>"
            if traps
            else "<p>No world has a single-run pair that contradicts its means.</p>",
            trap_picture,
            id="trap",
        ),
    ]
    page = atomic_write_text(
        out / COMPARE_PAGE,
        h.page(
            f"Comparison: {name_b} vs {name_a}",
            body,
            subtitle="Lower errors are better; differences are B \u2212 A.",
            nav=[
                ("campaigns", "Campaigns"),
                ("verdict", "Verdict"),
                ("per-world", "Per world"),
                ("trap", "Fig. 6 trap"),
            ],
        ),
    )
    figs.clean()
    return CompareReport(comparison, page, table_csv, tuple(figs.written), tuple(notes), (data_a.folder, data_b.folder))
