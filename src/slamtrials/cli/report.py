"""``slamtrials report``, ``compare`` and ``export-table``: thin wrappers over :mod:`slamtrials.report`.

* ``report CAMPAIGN [--out DIR] [--run WORLD/IDX] [--repeats N] [--seed S] [--no-pdf]``: write the HTML
  report (``CAMPAIGN/report/index.html``, figures beside it) and print Table I and the page's path.
* ``compare A B [--out DIR] [--alpha 0.05] [--correction holm|bh|none]``: compare two campaigns on their
  common worlds; print every setting that differs between them (``slam.preset: paper -> null``), which
  test (``paired (B is a replay of A)``: paired t per world with a Wilcoxon check; or ``unpaired
  (Welch)``), then per world and metric the difference B - A with its interval corrected like the
  p-values (Bonferroni's simultaneous one for Holm), the corrected p-value, the verdict and the share of
  single-run pairs that reverse it (the paper's Fig. 6 trap), then the overall verdicts (Stouffer's
  combined test); write ``compare.html`` and ``comparison.csv`` (default folder ``B/report/compare-<A>``).
* ``export-table CAMPAIGN --format csv|parquet [--table runs|worlds] [--out FILE]``: the runs (or worlds)
  as a file for pandas, R or a spreadsheet.
"""

from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import fmt_number, make_console, table_one

__all__ = ["report", "compare", "export_table", "register", "comparison_table", "worlds_table"]


class CorrectionChoice(str, Enum):
    holm = "holm"
    bh = "bh"
    none = "none"


class FormatChoice(str, Enum):
    csv = "csv"
    parquet = "parquet"


class TableChoice(str, Enum):
    runs = "runs"
    worlds = "worlds"


def _agg() -> None:
    """The CLI chooses the matplotlib backend: Agg (files only, no display needed)."""
    import matplotlib

    matplotlib.use("Agg")


def report(
    campaign: Annotated[Path, typer.Argument(help="Campaign folder (finished or still running; it is only read).")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Folder of the page and its figures (default: CAMPAIGN/report).")
    ] = None,
    run: Annotated[
        str | None,
        typer.Option(
            "--run", help="Run of the relation-sampling check (Fig. 3) as WORLD/IDX (default: the first finished run)."
        ),
    ] = None,
    repeats: Annotated[
        int, typer.Option("--repeats", help="Samplings of the relation-sampling check (the paper: 200).")
    ] = 200,
    seed: Annotated[int, typer.Option("--seed", help="Seed of those samplings.")] = 0,
    pdf: Annotated[bool, typer.Option("--pdf/--no-pdf", help="Also save every figure as PDF.")] = True,
) -> None:
    """Write the HTML report of a campaign: Table I, the paper's Figs. 1, 3, 4, 5, 6, maps, provenance."""
    from slamtrials.report.build import build_report
    from slamtrials.report.load import load_campaign

    _agg()
    page = build_report(campaign, out, sampling_run=run, repeats=repeats, seed=seed, pdf=pdf)
    console = make_console()
    console.print(worlds_table(load_campaign(campaign)))
    console.print(f"Report: {page}", highlight=False, soft_wrap=True)


def worlds_table(data):
    """A rich Table of Table I from :func:`slamtrials.report.load_campaign` data (the catalog read read-only)."""
    import pandas as pd

    table = table_one(f"{data.kind.capitalize()} {data.folder}", data.confidence, "outliers", "right")
    done = data.done
    for _, w in data.worlds.iterrows():
        needed = w["runs_needed"]
        runs = f"{w['runs_done']}" + (f"/{needed}" if pd.notna(needed) and int(needed) > w["runs_done"] else "")
        cells = [
            fmt_number(w[f"{m}_{s}"], d) for m, d in (("eps_t", 3), ("eps_r", 4)) for s in ("mean", "std", "half_width")
        ]
        outliers = f"{w['eps_t_outliers']}/{w['eps_r_outliers']}" if (done["world"] == w["world"]).any() else "-"
        table.add_row(str(w["world"]), str(w["status"]), runs, *cells, outliers)
    return table


def comparison_table(comparison, metric: str):
    """A rich Table of one metric of a :class:`slamtrials.report.compare.Comparison`: one row per world."""
    from rich.table import Table

    name_a, name_b = comparison.labels
    unit = "m" if metric == "eps_t" else "rad"
    digits = 3 if metric == "eps_t" else 4
    paired = comparison.paired
    test = "paired t" if paired else "Welch"
    table = Table(
        title=f"{metric} ({unit}): {name_b} vs {name_a}, difference of mean errors B \u2212 A (lower is better)",
        caption=f"{comparison.pairing}; CI: {comparison.intervals[metric].label}; p ({test}) adjusted by "
        f"{comparison.correction}"
        + (f"; W: Wilcoxon signed-rank check, adjusted by {comparison.correction}" if paired else "")
        + "; trap: share of single-run pairs that reverse the means (paper Fig. 6)",
    )
    columns = [
        ("world", "left"),
        ("pairs" if paired else "runs A/B", "right"),
        ("mean A", "right"),
        ("mean B", "right"),
        ("B \u2212 A [CI]", "right"),
        ("p adj", "right"),
        *([("W adj", "right")] if paired else []),
        ("verdict", "left"),
        ("trap", "right"),
    ]
    longest = max((len(str(w)) for w in comparison.for_metric(metric)["world"]), default=5)
    for column, justify in columns:
        # world names whole (never cut), the verdict wraps
        table.add_column(
            column, justify=justify, no_wrap=column != "verdict", min_width=longest if column == "world" else None
        )
    short = {
        "A better": f"{name_a} better",
        "B better": f"{name_b} better",
        "no significant difference": "no sig. difference",
    }
    for _, r in comparison.for_metric(metric).iterrows():
        trap = "-" if r["trap_fraction"] != r["trap_fraction"] else f"{r['trap_fraction']:.0%}"
        interval = f"[{fmt_number(r['ci_adj_low'], digits)}, {fmt_number(r['ci_adj_high'], digits)}]"
        table.add_row(
            str(r["world"]),
            f"{r['n_a']}" if paired else f"{r['n_a']}/{r['n_b']}",
            fmt_number(r["mean_a"], digits),
            fmt_number(r["mean_b"], digits),
            f"{fmt_number(r['difference'], digits)} {interval}",
            fmt_number(r["p_adjusted"], 4),
            *([fmt_number(r["wilcoxon_p_adjusted"], 4)] if paired else []),
            short.get(r["verdict"], r["verdict"]),
            trap,
        )
    return table


def compare(
    campaign_a: Annotated[Path, typer.Argument(help="Campaign A (e.g. the original).")],
    campaign_b: Annotated[Path, typer.Argument(help="Campaign B (e.g. another algorithm, or a replay of A).")],
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Folder of compare.html and comparison.csv (default: B/report/compare-<A>)."),
    ] = None,
    alpha: Annotated[
        float,
        typer.Option(
            "--alpha", help="Significance level; the intervals beside the verdicts are corrected like the p-values."
        ),
    ] = 0.05,
    correction: Annotated[
        CorrectionChoice, typer.Option("--correction", help="Correction for multiple comparisons across worlds.")
    ] = CorrectionChoice.holm,
    pdf: Annotated[bool, typer.Option("--pdf/--no-pdf", help="Also save every figure as PDF.")] = True,
) -> None:
    """Compare two campaigns on the same worlds: paired tests for a replay (Welch's otherwise), corrected p-values
    and intervals, verdicts, Stouffer's overall test, the Fig. 6 trap."""
    from slamtrials.campaign.differences import campaign_differences
    from slamtrials.cli.campaign import print_differences
    from slamtrials.errors import ConfigError
    from slamtrials.report.build import REPORT_DIR
    from slamtrials.report.compare_page import compare_report, trap_sentences

    if not (0.0 < alpha < 1.0):
        raise ConfigError(f"--alpha must be strictly between 0 and 1, got {alpha}")
    _agg()
    folder = out if out is not None else campaign_b / REPORT_DIR / f"compare-{campaign_a.absolute().name}"
    result = compare_report(campaign_a, campaign_b, folder, alpha=alpha, correction=correction.value, pdf=pdf)
    console = make_console()
    if campaign_a.resolve() == campaign_b.resolve():
        typer.echo(f"warning: {campaign_a} is compared with itself: every difference is 0", err=True)
    print_differences(console, campaign_differences(campaign_a, campaign_b), str(campaign_a), str(campaign_b))
    comparison = result.comparison
    what = (
        "paired t on the run-by-run differences per world, Wilcoxon signed-rank as a check"
        if comparison.paired
        else "Welch's t-test per world"
    )
    overall_test = next(iter(comparison.overall.values())).test if comparison.overall else "-"
    console.print(
        f"test: {comparison.pairing}: {what}; p and intervals corrected by {comparison.correction}; "
        f"overall: {overall_test}",
        highlight=False,
        soft_wrap=True,
    )
    for metric in result.comparison.overall:
        console.print(comparison_table(result.comparison, metric))
    for note in result.notes:
        console.print(f"note: {note}", highlight=False, soft_wrap=True)
    traps = trap_sentences(result.comparison, "eps_t")
    for sentence in traps[:5]:
        console.print(f"single runs mislead in {sentence}", highlight=False, soft_wrap=True)
    if len(traps) > 5:
        console.print(f"... and in {len(traps) - 5} more worlds (see the page)", highlight=False)
    for overall in result.comparison.overall.values():
        console.print(f"overall: {overall.statement}", highlight=False, soft_wrap=True)
    console.print(f"Comparison: {result.page} (table: {result.table_csv})", highlight=False, soft_wrap=True)


def export_table(
    campaign: Annotated[Path, typer.Argument(help="Campaign folder.")],
    fmt: Annotated[FormatChoice, typer.Option("--format", "-f", help="File format.")] = FormatChoice.csv,
    table: Annotated[
        TableChoice, typer.Option("--table", "-t", help="runs: one row per run; worlds: one row per world (Table I).")
    ] = TableChoice.runs,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="File to write (default: CAMPAIGN/<table>.<format>).")
    ] = None,
) -> None:
    """Write a campaign's runs (or worlds) table as CSV or Parquet."""
    from slamtrials.report.load import export_table as export

    path = export(campaign, fmt.value, out, table=table.value)
    typer.echo(f"{table.value} table: {path}")


def register(app: typer.Typer) -> None:
    """Add the ``report``, ``compare`` and ``export-table`` commands to ``app``."""
    app.command("report")(report)
    app.command("compare")(compare)
    app.command("export-table")(export_table)
