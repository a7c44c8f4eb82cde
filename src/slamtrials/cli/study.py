"""``slamtrials study``: run, resume, watch and report studies (thin wrappers over slamtrials.study).

* ``study run STUDY.yaml --out DIR [--set key=value ...] [--scheduler ADDRESS] [--workers N]``: run every
  cell of a study as a campaign, all on one Dask client; the same command, or ``study run --out DIR``
  without a config, resumes. ``--set`` changes the base campaign (``--set runs.max_runs=5``: a capped,
  quicker study; the stored study config records it).
* ``study status DIR``: per cell and world, the status, runs done and errors so far.
* ``study report DIR [--out REPORT] [--alpha A] [--correction holm|bh|none]``: the study page.

Bad input (an axis key that is not a config key, a value out of its range, an empty axis, two axes on the
same key, a folder of another study) is one line on stderr and exit status 2, before anything is written.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import fmt_number, make_app, make_console, quiet_dask, sim_profile_line
from slamtrials.errors import ConfigError

__all__ = ["app", "register"]

app = make_app(help="Run, resume, watch and report studies: campaigns over a grid of settings.")

EXIT_INTERRUPTED = 130


class _Lines:
    """Progress as lines: one per finished world of a cell (and the profile line first, on stderr)."""

    def __init__(self, console, first: str | None):
        self.console = console
        self.first = first

    def __call__(self, cell: str, event) -> None:
        if self.first is not None:
            typer.echo(self.first, err=True)
            self.first = None
        if event.kind == "world_done":
            note = f" ({event.message})" if event.message else ""
            self.console.print(
                f"{cell}: {event.world}: {event.status} with {event.done} runs{note}", highlight=False, soft_wrap=True
            )
        elif event.kind == "run_failed":
            self.console.print(
                f"{cell}: {event.world}: run {event.index} failed: {event.message}", highlight=False, soft_wrap=True
            )


def _cells_table(status, title: str):
    from rich.console import JustifyMethod
    from rich.table import Table

    table = Table(title=title)
    columns: tuple[tuple[str, JustifyMethod], ...] = (
        ("cell", "left"),
        ("world", "left"),
        ("status", "left"),
        ("runs", "right"),
        ("eps_t mean (m)", "right"),
        ("+-", "right"),
        ("eps_r mean (rad)", "right"),
        ("+-", "right"),
        ("SLAM CPU s", "right"),
        ("SLAM MiB", "right"),
    )
    for column, justify in columns:
        table.add_column(column, justify=justify, overflow="fold", min_width=len(column) if column == "cell" else None)
    for cell in status.cells:
        if cell.campaign is None:
            table.add_row(cell.name, "-", "not started", "0", "-", "-", "-", "-", "-", "-")
            continue
        for row in cell.campaign.summary:
            t, r = row.eps_t, row.eps_r
            cost = row.cost
            table.add_row(
                cell.name,
                row.world,
                row.status,
                str(row.runs),
                fmt_number(t.mean if t else None, 3),
                fmt_number(t.half_width if t else None, 3),
                fmt_number(r.mean if r else None, 4),
                fmt_number(r.half_width if r else None, 4),
                fmt_number(cost.slam_cpu_s if cost else None, 1),
                fmt_number(cost.slam_peak_mib if cost else None, 1),
            )
    return table


@app.command("run")
def run(
    config: Annotated[
        Path | None, typer.Argument(help="Study config YAML (see docs/studies.md); omit to resume --out.")
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Study folder (default: 'output' of the config); an existing one is resumed."),
    ] = None,
    settings: Annotated[
        list[str] | None,
        typer.Option(
            "--set", help="Base campaign setting key=value (value read as YAML), e.g. runs.max_runs=5; repeatable."
        ),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            help="Address of a running Dask scheduler (tcp://host:8786) or its scheduler file (a .json written by "
            "dask scheduler --scheduler-file); default: a local cluster.",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option("--workers", "-j", help="Worker processes of the local cluster (default: one per core)."),
    ] = None,
) -> None:
    """Run a study: every cell a campaign, all on one Dask client, longest runs first (or resume one)."""
    from slamtrials.cli.slam import parse_settings
    from slamtrials.study import StudyConfig, run_study, study_status
    from slamtrials.study.run import prepare_study

    if config is None and out is None:
        raise ConfigError("give a study config, or --out DIR of a study to resume")
    if config is None and settings:
        raise ConfigError("--set needs the study config (a resumed study keeps its stored settings)")
    study = StudyConfig.from_yaml(config) if config is not None else None
    if study is not None and settings:
        study = study.with_campaign_settings(parse_settings(settings))
    prepared = prepare_study(study, out)  # every check, before anything is written or started
    console = make_console()
    console.print(
        f"study {prepared.folder}: {len(prepared.cells)} cells ({', '.join(c.name for c in prepared.cells)}) "
        f"x {len(prepared.entries[0].worlds)} worlds{'; resuming' if prepared.resumed else ''}",
        highlight=False,
        soft_wrap=True,
    )
    quiet_dask()
    try:
        result = run_study(
            prepared.config,
            prepared.folder,
            scheduler=scheduler,
            workers=workers,
            on_event=_Lines(console, sim_profile_line(prepared.cells[0].config.sim)),
        )
    except KeyboardInterrupt:
        typer.echo(f"interrupted; resume with: slamtrials study run --out {prepared.folder}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    if result.complete:
        console.print(
            f"{result.folder}: complete, every cell is finished; nothing to run "
            f"(see 'slamtrials study status {result.folder}')",
            highlight=False,
            soft_wrap=True,
        )
        return
    console.print(_cells_table(study_status(result.folder), f"Study {result.folder}"))
    for cell, cell_result in zip(result.cells, result.results, strict=True):
        for note in cell_result.notes:
            console.print(f"note: {cell.name}: {note}", highlight=False, soft_wrap=True)
    console.print(
        f"{result.runs_done} runs done ({result.runs_failed} failed) in {result.wall_time:.0f} s; "
        f"report: slamtrials study report {result.folder}",
        highlight=False,
        soft_wrap=True,
    )


@app.command("status")
def status(folder: Annotated[Path, typer.Argument(help="Study folder.")]) -> None:
    """Show a study's progress: per cell and world, its status, runs done and the errors so far."""
    from slamtrials.study import study_status

    state = study_status(folder)
    console = make_console()
    axes = ", ".join(f"{k}: {v}" for k, v in state.config.axes.items()) or "none"
    combos = ", ".join(state.config.combinations) or "none"
    console.print(
        f"{folder}: study of {len(state.cells)} cells; axes {axes}; combinations {combos}; created {state.created}",
        highlight=False,
        soft_wrap=True,
        markup=False,
    )
    console.print(_cells_table(state, "Cells"))
    progress = "finished" if state.finished else f"not finished (resume with 'slamtrials study run --out {folder}')"
    console.print(f"{state.runs_done} runs done; {progress}", highlight=False, soft_wrap=True)


@app.command("report")
def report(
    folder: Annotated[Path, typer.Argument(help="Study folder (finished or not; it is only read).")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Folder of the page and its figures (default: STUDY/report).")
    ] = None,
    alpha: Annotated[float, typer.Option("--alpha", help="Significance level of the paired comparisons.")] = 0.05,
    correction: Annotated[
        str, typer.Option("--correction", help="Multiple-comparison correction: holm, bh or none.")
    ] = "holm",
    pdf: Annotated[bool, typer.Option("--pdf/--no-pdf", help="Also write each figure as PDF.")] = True,
) -> None:
    """Write the study page: error against each axis per world, every cell, paired comparisons, cost."""
    from slamtrials.study.report import build_study_report

    if correction not in ("holm", "bh", "none"):
        raise ConfigError(f"--correction: expected holm, bh or none, got {correction!r}")
    if not (0.0 < alpha < 1.0):
        raise ConfigError(f"--alpha: must be strictly between 0 and 1, got {alpha}")
    page = build_study_report(folder, out, alpha=alpha, correction=correction, pdf=pdf)  # type: ignore[arg-type]
    console = make_console()
    for line in page.summary_lines:
        console.print(line, highlight=False, soft_wrap=True, markup=False)
    console.print(f"study report: {page.page}", highlight=False, soft_wrap=True)


def register(root: typer.Typer) -> None:
    """Add the ``study`` command group to ``root``."""
    root.add_typer(app, name="study", help="Run, resume, watch and report studies (campaigns over a grid of settings).")
