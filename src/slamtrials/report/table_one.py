"""The report's Table I: per world, the runs' errors (mean, standard deviation, confidence half width, the
metric's share of the between-run variance), outliers, range and SLAM cost per run
(``<table id="summary-table">``, one row per world in the campaign's order), then the paper's printed
layout; what the columns mean, the metric share and the outlier rule are explained in a collapsed block."""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from slamtrials.report import html as h
from slamtrials.report.campaign_view import CampaignView
from slamtrials.report.load import CampaignData
from slamtrials.report.tables import METRICS, NOISE_SHARE_LIMIT, OUTLIER_IQR, SYMBOLS, paper_table, share_percent

__all__ = ["table_one_section", "SECTION_ID"]

#: The section's anchor.
SECTION_ID = "table-1"

#: The colour of a world's row by its status (None: plain).
_ROW_CLASSES = {"failed": "bad", "capped": "warn", "short": "warn", "done": None}


def table_one_section(view: CampaignView) -> str:
    """The section (HTML, ``id="table-1"``): Table I, a one-line caption, the explanations collapsed, and
    when runs have finished the paper's printed tables of ``eps_t`` and ``eps_r``."""
    data, done = view.data, view.done
    parts = [
        '<p id="summary-lead">'
        + h.esc(
            f"Per world: the runs' mean, standard deviation and {h.fmt_percent(data.confidence)} confidence half "
            "width of each error, and what SLAM cost per run; what each column is, below the table."
        )
        + "</p>",
        h.scrolling(_summary_table(data, done)),  # as wide as the page: the table scrolls sideways when wider
        h.details(
            "What the columns mean: runs, errors, metric share, outliers, cost",
            h.explanation(_caption(data), id="summary-caption"),
            _share_note(data),
            _outlier_note(),
            css_class="explain",
        ),
    ]
    if len(done):
        summary = data.worlds[data.worlds["runs_done"] > 0]
        for metric, unit in (("eps_t", "m"), ("eps_r", "rad")):
            printed = paper_table(summary, metric, population=True)
            rows = [
                [label, *[h.number_cell(v, 3 if metric == "eps_t" else 4) for v in printed.loc[label]]]
                for label in printed.index
            ]
            caption = f"As printed in the paper: {SYMBOLS[metric]} ({unit}) per world, std dev with divisor n (Definition III.3)."
            parts.append(
                h.scrolling(h.table(["", *printed.columns], rows, id=f"paper-table-{metric}", caption=caption))
            )
    return h.section("Table I: localization error per world", *parts, id=SECTION_ID)


def _summary_table(data: CampaignData, done: pd.DataFrame) -> str:
    """``<table id="summary-table">``: one row per world of ``data.worlds``, coloured by its status."""
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
    ]
    groups = [
        ("", 3),
        (f"{SYMBOLS['eps_t']} (m)", 4),
        (f"{SYMBOLS['eps_r']} (rad)", 4),
        ("", 2),
        ("SLAM cost per run", 3),
    ]
    rows = []
    for _, w in data.worlds.iterrows():
        needed = w["runs_needed"]
        runs = f"{w['runs_done']}" + (f" / {needed}" if pd.notna(needed) and int(needed) > w["runs_done"] else "")
        if w["capped"] and pd.notna(w["runs_target"]):
            runs += f" (capped at {w['runs_target']})"
        cells = [w["world"], w["status"], h.Cell(runs, numeric=True)]
        for metric, digits in (("eps_t", 3), ("eps_r", 4)):
            cells += [
                h.number_cell(w[f"{metric}_mean"], digits),
                h.number_cell(w[f"{metric}_std"], digits),
                h.number_cell(w[f"{metric}_half_width"], digits),
                _share_cell(w[f"{metric}_metric_share"]) if w["runs_done"] else h.Cell("-", numeric=True),
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
            h.seconds_cell(w["slam_cpu_s_mean"]),
            h.Cell(
                _update_text(w["update_ms_median_mean"], w["update_ms_p90_mean"]),
                numeric=True,
                title="median / 90th percentile of the time per SLAM update (ms), mean over the runs",
            ),
            h.seconds_cell(w["slam_peak_mib_mean"]),
        ]
        rows.append(cells)
    classes = [_ROW_CLASSES.get(status, "warn") for status in data.worlds["status"]]
    return h.table(header, rows, id="summary-table", row_classes=classes, groups=groups)


def _caption(data: CampaignData) -> str:
    """What the columns of Table I are."""
    return (
        f"The paper's Table I: per world, the mean and sample standard deviation (divisor n \u2212 1) of the runs' "
        f"translational error {SYMBOLS['eps_t']} (m) and rotational error {SYMBOLS['eps_r']} (rad), and the half width "
        f"of the {h.fmt_percent(data.confidence)} confidence interval of the mean. Runs: done (/ needed by the "
        "run-count rule when more, also where the cap stopped a world). SLAM cost per run: the mean over the runs of "
        "the SLAM algorithm's CPU time (s), of its time per update (ms, median / 90th percentile) and of its peak "
        "memory (MiB), as the section on cost defines them; - where not measured. How the runs ended is in its own "
        "section, and a world's notes are in the overview's."
    )


def _share_cell(value: Any) -> h.Cell:
    """The metric's share of the between-run variance as a percentage; ``n/a`` when it is not known."""
    if value is None or not math.isfinite(float(value)):
        return h.Cell("n/a", numeric=True, title="no standard errors recorded for these runs, or fewer than 2 runs")
    return h.Cell(share_percent(float(value)), numeric=True)


def _update_text(median: Any, p90: Any) -> str:
    """``median / p90`` of the time per update (ms), ``-`` where not measured."""
    if not (isinstance(median, (int, float)) and math.isfinite(median)):
        return "-"
    return f"{h.fmt_seconds(median)} / {h.fmt_seconds(p90)}"


def _share_note(data: CampaignData) -> str:
    """The paragraph that says what the metric-share columns are, and which worlds reach 10 %."""
    limit = h.fmt_percent(NOISE_SHARE_LIMIT)
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
    return h.explanation(text, id="metric-share-note")


def _outlier_note() -> str:
    """The paragraph that says how the outlier column is counted."""
    text = (
        f"Outliers: how many of the world's finished runs lie beyond Tukey's fences, for {SYMBOLS['eps_t']} / "
        f"{SYMBOLS['eps_r']}: more than {OUTLIER_IQR:g} interquartile ranges (IQR = Q3 \u2212 Q1) below the first "
        "quartile Q1 or above the third quartile Q3 of that world's run errors (quartiles by linear "
        "interpolation), the whiskers of Fig. 5's boxes. An outlier is a run unusual among its world's runs, not "
        "a failed one (failed runs have no error); with few runs the quartiles are rough, so an outlier there is "
        "a hint, and where the metric share is high it may be the metric's noise. The runs table at the end marks "
        "each outlier run."
    )
    return h.explanation(text, id="outlier-note")
