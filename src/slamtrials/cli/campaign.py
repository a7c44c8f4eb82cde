"""``slamtrials campaign``: run, resume, watch and replay campaigns (thin wrappers over slamtrials.campaign).

* ``campaign run CONFIG.yaml --out DIR [--scheduler ADDRESS] [--workers N]``: run a campaign; the same
  command, or ``campaign run --out DIR`` without a config, resumes an interrupted one.
* ``campaign status DIR``: progress and the summary so far.
* ``campaign replay DIR [--algorithm NAME] [--preset P | --no-preset] [--set key=value ...] --out NEW``:
  evaluate another SLAM algorithm or configuration on the recorded runs of DIR, without simulating. The
  replay keeps DIR's algorithm, preset and parameters and changes only what is given; it first prints
  every setting that differs from DIR's (``slam.params.particles: 40 -> 80``).

Resuming a campaign (or replay) that is already complete prints one line saying so and exits 0.

The end of ``run`` and ``replay`` is the per-world table (the paper's Table I: runs, mean and standard
deviation of eps_t and eps_r, confidence intervals), also saved as ``DIR/summary.csv``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import fmt_number, make_app, make_console, quiet_dask, sim_profile_line, table_one
from slamtrials.cli.costtext import world_cost_line
from slamtrials.cli.slam import ProgramInputOpt, ProgramOpt, ProgramOutputOpt, TimeoutOpt
from slamtrials.errors import ConfigError

__all__ = ["app", "register", "summary_table", "print_differences", "EXIT_INTERRUPTED"]

app = make_app(help="Run, resume, watch and replay campaigns: repeat runs until every world's error is known.")

EXIT_INTERRUPTED = 130

SchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help="Address of a running Dask scheduler (e.g. tcp://host:8786) or its scheduler file (a .json written by "
        "dask scheduler --scheduler-file); default: a local cluster.",
    ),
]
WorkersOpt = Annotated[
    int | None, typer.Option("--workers", "-j", help="Worker processes of the local cluster (default: one per core).")
]


def summary_table(rows, confidence: float, title: str):
    """A rich Table of summary rows (:class:`slamtrials.campaign.WorldSummary`), the paper's Table I."""
    table = table_one(title, confidence, "runs ended by")
    for row in rows:
        cells = []
        for stats in (row.eps_t, row.eps_r):
            if stats is None:
                cells += ["-", "-", "-"]
            else:
                digits = 3 if stats is row.eps_t else 4
                cells += [
                    fmt_number(stats.mean, digits),
                    fmt_number(stats.std_sample, digits),
                    fmt_number(stats.half_width, digits),
                ]
        needed = f"/{row.runs_needed}" if row.runs_needed is not None and row.runs_needed > row.runs else ""
        if row.cap is not None:
            needed += f" (capped at {row.cap})"
        reasons = ", ".join(f"{k} {v}" for k, v in row.terminations.items())
        table.add_row(row.world, row.status, f"{row.runs}{needed}", *cells, reasons)
    return table


def _needed_cell(world) -> str:
    """The runs a world needs (a :class:`~slamtrials.campaign.store.WorldRow`): the current batch's target,
    or where the cap stopped it, the rule's figure and the cap."""
    if world.capped and world.runs_needed is not None:
        return f"{world.runs_needed} (capped at {world.runs_target})"
    return "-" if world.runs_target is None else str(world.runs_target)


def metric_share_line(rows) -> str | None:
    """One line: per world, the metric's share of the between-run variance of eps_t / eps_r; None if unknown."""
    from slamtrials.report.tables import share_percent

    parts = []
    for row in rows:
        if row.metric_share_t is None or row.metric_share_r is None:
            continue
        parts.append(f"{row.world} {share_percent(row.metric_share_t)} / {share_percent(row.metric_share_r)}")
    if not parts:
        return None
    return (
        "metric's share of the between-run variance (eps_t / eps_r; the runs' mean squared standard error over the "
        "variance of their errors; below 10 % the differences between runs are real): " + ", ".join(parts)
    )


class _Progress:
    """Progress bars per world, fed by campaign events; a line per finished world when not a terminal.

    ``first`` (e.g. the :func:`~slamtrials.cli.common.profile_line`) is printed on stderr with the first
    event, which comes after every check of the input, so that bad input stays a one-line error.
    """

    def __init__(self, console, first: str | None = None):
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self.console = console
        self.progress = Progress(
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[status]}"),
            TimeElapsedColumn(),
            # the time left for the runs the rule asks for so far (it may ask for more)
            TimeRemainingColumn(),
            console=console,
            disable=not console.is_terminal,
        )
        self.tasks: dict[str, int] = {}
        self.first = first

    def __enter__(self):
        self.progress.__enter__()
        return self

    def __exit__(self, *exc):
        self.progress.__exit__(*exc)

    def __call__(self, event) -> None:
        if self.first is not None:
            typer.echo(self.first, err=True)
            self.first = None
        task = self.tasks.get(event.world)
        if task is None:
            task = self.tasks[event.world] = self.progress.add_task(
                event.world, total=max(event.target, event.done), status=""
            )
        total = max(event.target, event.done)
        if event.kind == "run_failed":
            self.progress.update(task, completed=event.done, total=total, status=f"run {event.index} failed")
        elif event.kind == "world_done":
            self.progress.update(
                task, completed=event.done, total=event.done if event.status != "short" else total, status=event.status
            )
            self.console.print(
                f"{event.world}: {event.status} with {event.done} runs"
                f"{' (' + event.message + ')' if event.message else ''}",
                highlight=False,
                soft_wrap=True,
            )
        else:
            status = "running" if event.kind != "start" else (event.status or "")
            self.progress.update(task, completed=event.done, total=total, status=status)


def _finish(console, result, config_confidence: float, title: str) -> None:
    console.print(summary_table(result.summary, config_confidence, title))
    for line in (metric_share_line(result.summary), world_cost_line(result.summary)):
        if line:
            console.print(line, highlight=False, soft_wrap=True)
    for note in result.notes:
        console.print(f"note: {note}", highlight=False, soft_wrap=True)
    console.print(
        f"{result.runs_done} runs done ({result.runs_failed} failed) in {result.wall_time:.0f} s; "
        f"summary: {result.summary_csv}",
        highlight=False,
        soft_wrap=True,
    )


@app.command("run")
def run(
    config: Annotated[
        Path | None,
        typer.Argument(help="Campaign config YAML ('slamtrials config dump' prints one); omit to resume --out."),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out", "-o", help="Campaign folder (default: 'output' of the config); an existing one is resumed."
        ),
    ] = None,
    scheduler: SchedulerOpt = None,
    workers: WorkersOpt = None,
) -> None:
    """Run a campaign: per world, repeat runs until its mean errors are known (or resume one).

    Prints the error profile of its runs (``profile: realistic`` unless the config names another) on
    stderr when the runs start.
    """
    from slamtrials.campaign import CampaignConfig, run_campaign
    from slamtrials.campaign.store import CampaignStore, is_campaign

    if config is None and out is None:
        raise ConfigError("give a campaign config, or --out DIR of a campaign to resume")
    campaign_config = CampaignConfig.from_yaml(config) if config is not None else None
    if campaign_config is None and not is_campaign(out):
        raise ConfigError(f"{out}: not a campaign folder (campaign.sqlite missing); give a config to start one")
    if campaign_config is None:
        with CampaignStore.open(out) as store:
            sim = store.config().sim
            confidence = store.config().runs.confidence
    else:
        sim = campaign_config.sim
        confidence = campaign_config.runs.confidence
    quiet_dask()
    console = make_console()
    folder = out or (Path(campaign_config.output) if campaign_config and campaign_config.output else None)
    try:
        with _Progress(console, first=sim_profile_line(sim)) as progress:
            result = run_campaign(campaign_config, out, scheduler=scheduler, workers=workers, on_event=progress)
    except KeyboardInterrupt:
        typer.echo(f"interrupted; resume with: slamtrials campaign run --out {folder}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    if result.complete:
        _say_complete(console, result)
        return
    _finish(console, result, confidence, f"Campaign {result.folder}")


def _say_complete(console, result) -> None:
    console.print(
        f"{result.folder}: complete, every world is finished; nothing to run "
        f"(see 'slamtrials campaign status {result.folder}')",
        highlight=False,
        soft_wrap=True,
    )


@app.command("status")
def status(folder: Annotated[Path, typer.Argument(help="Campaign folder.")]) -> None:
    """Show a campaign's progress: per world, its status, runs done and needed, and the errors so far."""
    from rich.table import Table

    from slamtrials.campaign import campaign_status

    state = campaign_status(folder)
    console = make_console()
    config = state.config
    what = f"replay of {config.replay_of}" if state.kind == "replay" else "campaign"
    interrupted = state.interrupted
    console.print(
        f"{folder}: {what}, algorithm {config.slam.algorithm} (preset {config.slam.preset}), "
        f"profile {config.sim.profile_label}, seed {config.seed}, "
        f"runs: initial {config.runs.initial}, cap {config.runs.max_runs}, margins {config.runs.margin_t:g} m / "
        f"{config.runs.margin_r:g} rad at {100 * config.runs.confidence:g} %; relations: "
        f"{config.metric.sampling.describe()}; created {state.created}",
        highlight=False,
        soft_wrap=True,
    )
    table = Table(title="Progress")
    for column, justify in (
        ("world", "left"),
        ("status", "left"),
        ("done", "right"),
        ("needed", "right"),
        ("interrupted" if interrupted else "running", "right"),
        ("failed", "right"),
        ("note", "left"),
    ):
        table.add_column(column, justify=justify)
    for world in state.worlds:
        counts = state.runs.get(world.name, {})
        table.add_row(
            world.name,
            world.status,
            str(counts.get("done", 0)),
            _needed_cell(world),
            str(counts.get("interrupted" if interrupted else "running", 0)),
            str(counts.get("failed", 0)),
            world.note or "",
        )
    console.print(table)
    console.print(summary_table(state.summary, config.runs.confidence, "Errors so far"))
    for line in (metric_share_line(state.summary), world_cost_line(state.summary)):
        if line:
            console.print(line, highlight=False, soft_wrap=True)
    if state.finished:
        progress = "finished"
    elif state.driver is False:
        again = "campaign run --out" if state.kind == "campaign" else "campaign replay ... --out"
        cause = "interrupted; " if interrupted else ""
        progress = f"not finished, no driver alive ({cause}resume with 'slamtrials {again} {folder}')"
    else:
        progress = "not finished"
    console.print(f"{state.runs_done} runs done; {progress}", highlight=False, soft_wrap=True)


@app.command("replay")
def replay(
    source: Annotated[Path, typer.Argument(help="Folder of the campaign whose recorded runs are re-evaluated.")],
    out: Annotated[
        Path, typer.Option("--out", "-o", help="Folder of the new campaign (an existing replay is resumed).")
    ],
    algorithm: Annotated[
        str | None,
        typer.Option(
            "--algorithm",
            "-a",
            help="SLAM algorithm to evaluate (built-in: gmapping, karto, odometry); default: the source's.",
        ),
    ] = None,
    preset: Annotated[
        str | None,
        typer.Option(
            "--preset",
            "-p",
            help="Named parameter set of the algorithm; default: the source's for its algorithm, none for another.",
        ),
    ] = None,
    no_preset: Annotated[
        bool, typer.Option("--no-preset", help="Run the algorithm's defaults (with the overrides), no preset.")
    ] = False,
    settings: Annotated[
        list[str] | None,
        typer.Option(
            "--set",
            help="Parameter override key=value (value read as YAML), on top of the source's parameters; repeatable.",
        ),
    ] = None,
    program: ProgramOpt = None,
    program_input: ProgramInputOpt = "carmen",
    program_output: ProgramOutputOpt = "tum",
    timeout: TimeoutOpt = 3600.0,
    scheduler: SchedulerOpt = None,
    workers: WorkersOpt = None,
) -> None:
    """Evaluate another SLAM algorithm, configuration or program on a campaign's recorded runs, with no simulation.

    The replay keeps the source's algorithm, preset and parameters and changes only what is given. A
    --program gets each run's odometry and laser (no ground truth); a run it fails on is a failed run
    with its exit code and the end of its stderr.
    """
    from slamtrials.campaign import REPLAY_NOTE, replay_campaign
    from slamtrials.campaign.differences import setting_differences
    from slamtrials.campaign.replay import SOURCE_PRESET, replay_config
    from slamtrials.campaign.store import CampaignStore
    from slamtrials.cli.slam import parse_settings, program_option

    if preset is not None and no_preset:
        raise ConfigError("give --preset NAME or --no-preset, not both")
    chosen = None if no_preset else (SOURCE_PRESET if preset is None else preset)
    params = parse_settings(settings or [])
    spec = program_option(program, program_input, program_output, timeout)
    with CampaignStore.open(source) as store:
        base = store.config()
    config = replay_config(base, source, out, algorithm, chosen, params, spec)  # checks the settings before any output
    quiet_dask()
    console = make_console()
    print_differences(console, setting_differences(base, config), str(source), str(out))
    console.print(f"note: {REPLAY_NOTE}", highlight=False, soft_wrap=True)
    try:
        with _Progress(console) as progress:
            result = replay_campaign(
                source,
                out,
                algorithm,
                chosen,
                params,
                program=spec,
                scheduler=scheduler,
                workers=workers,
                on_event=progress,
            )
    except KeyboardInterrupt:
        typer.echo("interrupted; resume with the same command", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    if result.complete:
        _say_complete(console, result)
        return
    _finish(console, result, base.runs.confidence, f"Replay of {source} with {config.slam.algorithm}")


def print_differences(console, differences, name_a: str, name_b: str) -> None:
    """Print the settings that differ from campaign ``name_a`` to ``name_b``, one line each (or that none do)."""
    if not differences:
        console.print(f"settings: {name_b} has the same settings as {name_a}", highlight=False, soft_wrap=True)
        return
    console.print(f"settings that differ ({name_a} -> {name_b}):", highlight=False, soft_wrap=True)
    for difference in differences:
        console.print(f"  {difference}", highlight=False, soft_wrap=True, markup=False)


def register(root: typer.Typer) -> None:
    """Add the ``campaign`` command group to ``root``."""
    root.add_typer(app, name="campaign", help="Run, resume, watch and replay campaigns.")
