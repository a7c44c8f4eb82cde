"""``slamtrials demo``: the README's main job: a small campaign on bundled worlds, then its HTML report.

``slamtrials demo --out results/demo [--workers N] [--world NAME ...] [--seed S]`` runs (or resumes) the
demo campaign in the folder ``--out`` (:func:`slamtrials.demo.run_demo`), shows progress per world, and
ends with the per-world summary (the paper's Table I) and the path of ``report/index.html``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import make_console


def demo(
    out: Annotated[
        Path, typer.Option("--out", "-o", help="Campaign folder (an existing demo campaign there is resumed).")
    ] = Path("results/demo"),
    workers: Annotated[
        int | None,
        typer.Option("--workers", "-j", help="Worker processes of the local Dask cluster (default: one per core)."),
    ] = None,
    world: Annotated[
        list[str] | None,
        typer.Option(
            "--world", "-w", help="Bundled world or floor-plan file (repeatable; default: three small buildings)."
        ),
    ] = None,
    seed: Annotated[int, typer.Option("--seed", "-s", help="Root seed of the campaign.")] = 0,
) -> None:
    """Run a small campaign (online GMapping, autonomous exploration) on bundled worlds and write its HTML report.

    Its runs simulate with the default error profile (``profile: realistic`` is printed on stderr).
    """
    import matplotlib

    from slamtrials.campaign.cluster import check_workers
    from slamtrials.cli.campaign import EXIT_INTERRUPTED, _Progress, metric_share_line, summary_table
    from slamtrials.cli.common import quiet_dask, sim_profile_line
    from slamtrials.cli.costtext import world_cost_line
    from slamtrials.demo import DEMO_WORLDS, demo_config, run_demo

    matplotlib.use("Agg")
    check_workers(workers)  # a bad --workers is one line before anything starts
    worlds = tuple(world) if world else DEMO_WORLDS
    quiet_dask()
    console = make_console()
    intro = [
        f"Demo campaign in {out}: {', '.join(worlds)}; per world the runs repeat until its mean error is known "
        "(99 % confidence, +-0.02 m / +-0.02 rad) or the cap of 10 runs."
    ]

    profile = sim_profile_line(demo_config(out, worlds, seed=seed).sim)

    def on_event(event, progress) -> None:
        if intro:  # the first event comes after every check, so bad input stays a one-line error
            typer.echo(profile, err=True)
            console.print(intro.pop(), highlight=False, soft_wrap=True)
        progress(event)

    try:
        with _Progress(console) as progress:
            result = run_demo(out, worlds, seed=seed, workers=workers, on_event=lambda event: on_event(event, progress))
    except KeyboardInterrupt:
        typer.echo(f"interrupted; resume with: slamtrials demo --out {out}", err=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    campaign = result.campaign
    console.print(summary_table(campaign.summary, result.confidence, f"Demo campaign {campaign.folder}"))
    for line in (metric_share_line(campaign.summary), world_cost_line(campaign.summary)):
        if line:
            console.print(line, highlight=False, soft_wrap=True)
    for note in campaign.notes:
        console.print(f"note: {note}", highlight=False, soft_wrap=True)
    console.print(
        f"{campaign.runs_done} runs done ({campaign.runs_failed} failed) in {campaign.wall_time:.0f} s; "
        f"summary: {campaign.summary_csv}",
        highlight=False,
        soft_wrap=True,
    )
    console.print(f"Report: {result.report}", highlight=False, soft_wrap=True)


def register(app: typer.Typer) -> None:
    """Add the ``demo`` command to ``app``."""
    app.command("demo")(demo)
