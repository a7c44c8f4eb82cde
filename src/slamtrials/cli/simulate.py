"""``slamtrials simulate``: drive a scripted path through a world and write a run folder."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from slamtrials.cli.common import make_console, say_profile
from slamtrials.errors import ConfigError

if TYPE_CHECKING:
    from slamtrials.metric.relationset import RelationSet
    from slamtrials.record import RunRecord


def simulate(
    world: Annotated[str, typer.Option("--world", "-w", help="Bundled world name or floor-plan file.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Run folder to write (frames.npz, run.json, run.png).")],
    path: Annotated[
        Path | None,
        typer.Option("--path", "-p", help="Waypoint YAML ('waypoints: [\\[x, y], ...]', metres, world frame)."),
    ] = None,
    tour: Annotated[
        bool, typer.Option("--tour", help="Instead of --path, drive an automatic tour to the far corners of the world.")
    ] = False,
    seed: Annotated[
        int, typer.Option("--seed", "-s", help="Seed of every random draw of the run (odometry bias, noise).")
    ] = 0,
    max_time: Annotated[float, typer.Option("--max-time", help="Stop after this much simulated time (s).")] = 3600.0,
    resolution: Annotated[
        float | None, typer.Option("--resolution", help="Metres per pixel, for a bare PNG/PGM floor plan.")
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace a run already stored in --out.")] = False,
    config: Annotated[
        Path | None,
        typer.Option(
            "--config",
            "-c",
            help="YAML with profile/robot/laser/odometry/dt settings (SI units); default: the paper's robot and "
            "laser with the realistic error profile (profile: paper for the paper's noise-free one).",
        ),
    ] = None,
) -> None:
    """Simulate the robot driving through WAYPOINTS (or a --tour) and record laser, odometry and ground truth.

    The run folder also gets its relation set (relations.npz, drawn with the run's seed), so every
    estimate of the run (slam, slam --program, evaluate --estimate) is scored on the same relations.

    Prints the error profile it simulates with (``profile: realistic`` by default) on stderr first.
    """
    from slamtrials.io.runfolder import RunFolder, write_run
    from slamtrials.io.waypoints import read_waypoints
    from slamtrials.io.yamlfile import read_yaml_mapping
    from slamtrials.report.runplot import save_run_figure
    from slamtrials.sim import SimConfig, simulate_waypoints
    from slamtrials.sim.overrides import warn_overrides
    from slamtrials.sim.tour import tour_waypoints
    from slamtrials.worlds import load_world

    if (path is None) == (not tour):
        raise ConfigError("give exactly one of --path WAYPOINTS.yaml or --tour")
    if seed < 0:
        raise ConfigError(f"--seed must be a non-negative integer, got {seed}")
    if not (max_time > 0):
        raise ConfigError(f"--max-time must be positive seconds, got {max_time}")
    if RunFolder(out).is_complete() and not overwrite:
        raise ConfigError(f"{out}: already holds a run; choose another --out or pass --overwrite")
    from slamtrials.campaign.profilefile import inline_profile_file

    sim_config = SimConfig()
    if config is not None:
        try:
            data = inline_profile_file({"sim": read_yaml_mapping(config)}, config.parent)["sim"]
            sim_config = SimConfig.from_dict(data)
        except ConfigError as exc:
            raise ConfigError(f"{config}: {exc}") from None
        warn_overrides(sim_config, str(config), prefix="")
    options = {} if resolution is None else {"resolution": resolution}
    the_world = load_world(world, **options)
    waypoints = read_waypoints(path) if path is not None else tour_waypoints(the_world)
    say_profile(sim_config)
    started = time.perf_counter()
    record = simulate_waypoints(the_world, waypoints, sim_config, seed=seed, max_time=max_time)
    wall = time.perf_counter() - started
    record.metadata.update(world_source=str(world), wall_time_s=round(wall, 3))
    write_run(out, record)
    relations = record_relation_set(out, record, seed)
    save_run_figure(the_world, record, RunFolder(out).picture, title=f"{the_world.name}, seed {seed}")
    console = make_console()
    duration = float(record.t[-1] - record.t[0])
    console.print(
        f"{out}: {len(record)} frames, {duration:.1f} s simulated in {wall:.2f} s "
        f"({duration / max(wall, 1e-9):.0f}x real time), outcome {record.metadata.get('outcome', '?')}; "
        f"relation set: {len(relations)} relations (seed {seed}), on which every estimate of it is scored",
        soft_wrap=True,
        highlight=False,
    )


def record_relation_set(out: Path, record: RunRecord, seed: int) -> RelationSet:
    """Draw the run's relation set (the campaign's default sampling, sized on the odometry, the run's seed)
    and store it as the folder's ``relations.npz``, so that every estimate of the run is scored on it."""
    from slamtrials.campaign.config import MetricSettings
    from slamtrials.campaign.relationsetfile import write_relation_set
    from slamtrials.campaign.score import run_relation_set
    from slamtrials.io.runfolder import RunFolder

    files = RunFolder(out)
    files.relation_set.unlink(missing_ok=True)  # an --overwrite'n run's old set is not this run's
    relation_set = run_relation_set(out, record, seed, MetricSettings())
    write_relation_set(files.relation_set, relation_set)
    return relation_set


def register(app: typer.Typer) -> None:
    """Add the ``simulate`` command to ``app``."""
    app.command("simulate")(simulate)
