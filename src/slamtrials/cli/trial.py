"""``slamtrials trial``: one autonomous exploration run with online SLAM, written as a run folder."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import make_console, say_profile
from slamtrials.errors import ConfigError

__all__ = ["trial", "register"]


def trial(
    world: Annotated[str, typer.Option("--world", "-w", help="Bundled world name or floor-plan file.")],
    out: Annotated[
        Path,
        typer.Option(
            "--out", "-o", help="Run folder to write (frames.npz, estimate.tum, map.yaml/.pgm/.png, run.json, run.png)."
        ),
    ],
    seed: Annotated[
        int, typer.Option("--seed", "-s", help="Seed of every random draw of the trial (simulator and SLAM).")
    ] = 0,
    config: Annotated[
        Path | None,
        typer.Option(
            "--config",
            "-c",
            help="YAML with sim/slam/explore/termination settings; default: the paper's set-up with the "
            "realistic error profile (sim: {profile: paper} for the paper's noise-free one).",
        ),
    ] = None,
    resolution: Annotated[
        float | None, typer.Option("--resolution", help="Metres per pixel, for a bare PNG/PGM floor plan.")
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace a run already stored in --out.")] = False,
) -> None:
    """Let the robot explore WORLD on its own, mapped online by SLAM, until the map stops changing.

    Prints the error profile it simulates with (``profile: realistic`` by default) on stderr first.
    """
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from slamtrials.campaign.config import MetricSettings
    from slamtrials.campaign.mapscore import add_map_quality
    from slamtrials.campaign.profilefile import inline_profile_file
    from slamtrials.campaign.score import score_run
    from slamtrials.campaign.task import write_scored_run
    from slamtrials.cli.costtext import run_cost_text
    from slamtrials.cli.explorationtext import exploration_text
    from slamtrials.cli.mapqualitytext import map_quality_text
    from slamtrials.cost import RunCost
    from slamtrials.io.runfolder import RunFolder
    from slamtrials.io.yamlfile import read_yaml_mapping
    from slamtrials.report.runplot import save_run_figure
    from slamtrials.sim.overrides import warn_overrides
    from slamtrials.trial import TrialConfig, TrialSummary, run_trial
    from slamtrials.trial.exploration import ExplorationMeasures
    from slamtrials.worlds import load_world

    if seed < 0:
        raise ConfigError(f"--seed must be a non-negative integer, got {seed}")
    if RunFolder(out).is_complete() and not overwrite:
        raise ConfigError(f"{out}: already holds a run; choose another --out or pass --overwrite")
    trial_config = TrialConfig()
    if config is not None:
        try:
            trial_config = TrialConfig.from_dict(inline_profile_file(read_yaml_mapping(config), config.parent))
        except ConfigError as exc:
            raise ConfigError(f"{config}: {exc}") from None
        warn_overrides(trial_config.sim, str(config))
    the_world = load_world(world, **({} if resolution is None else {"resolution": resolution}))
    say_profile(trial_config.sim)
    console = make_console()
    columns = (TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[status]}"), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        task = progress.add_task(f"{the_world.name} seed {seed}", total=trial_config.termination.max_time, status="")

        def report(p) -> None:
            progress.update(
                task,
                completed=p.t,
                status=f"{p.t:6.0f} s simulated, {p.known_free_area:7.0f} of {p.reachable_area:.0f} m^2 mapped",
            )

        record = run_trial(the_world, trial_config, seed, on_progress=report)
    record.metadata.update(world_source=str(world))
    metric = MetricSettings()
    score = score_run(record, seed, metric)
    record.metadata["evaluation"] = {**score.to_dict(), "metric": metric.model_dump(mode="json")}
    quality = add_map_quality(record, the_world)
    write_scored_run(Path(out), record, score)
    save_run_figure(the_world, record, RunFolder(out).picture, title=f"{the_world.name}, seed {seed}")
    info = TrialSummary.of(record)
    assert info is not None  # run_trial always stores it
    console.print(
        f"{out}: {info.termination_reason} after {info.duration_s:.0f} s simulated in {info.wall_time_s:.1f} s "
        f"({info.realtime_factor:.0f}x real time); mapped {100 * info.mapped_fraction:.1f} % of the reachable "
        f"{info.reachable_area_m2:.0f} m^2, travelled {info.distance_m:.0f} m, {info.slam_updates} SLAM updates",
        soft_wrap=True,
        highlight=False,
    )
    console.print(run_cost_text(RunCost.of(record.metadata)), soft_wrap=True, highlight=False)
    console.print(exploration_text(ExplorationMeasures.of(record.metadata)), soft_wrap=True, highlight=False)
    console.print(map_quality_text(quality), soft_wrap=True, highlight=False)
    odometry = score.odometry
    console.print(
        f"error over {len(score.relation_set)} relations (relations.npz): translational {score.eps_t:.4f} m "
        f"(standard error {score.estimate.se_t:.2g}), rotational {score.eps_r:.4f} rad (standard error "
        f"{score.estimate.se_r:.2g}); odometry alone {odometry.eps_t:.4f} m, {odometry.eps_r:.4f} rad",
        soft_wrap=True,
        highlight=False,
    )


def register(app: typer.Typer) -> None:
    """Add the ``trial`` command to ``app``."""
    app.command("trial")(trial)
