"""``slamtrials validate``: the paper's Section IV on a real log (a thin wrapper over :mod:`slamtrials.validation`).

Reads the log and its relations, resolves the profile, runs :func:`slamtrials.validation.validate`
(replicas sequentially, or on Dask with ``--workers N > 1`` or ``--scheduler``), prints the real error
next to the replicas' mean +- std like the paper's Tables II and III, and writes ``--json`` and
``--figure`` when asked. Bad input (files that do not belong together, an unknown profile) is one line
and exit status 2, before anything runs or is written.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from slamtrials.cli.common import fmt_number, make_console, quiet_dask, say_profile
from slamtrials.cli.slam import (
    ProgramInputOpt,
    ProgramOpt,
    ProgramOutputOpt,
    TimeoutOpt,
    parse_settings,
    program_option,
)
from slamtrials.errors import ConfigError

if TYPE_CHECKING:
    from slamtrials.sim.profiles import ErrorProfile
    from slamtrials.validation import ReplicaResult, ValidationPlan, ValidationResult

__all__ = ["validate", "register", "resolve_profile_option", "format_validation", "write_figure"]


def resolve_profile_option(value: str) -> ErrorProfile:
    """``--profile``: a bundled profile's name or a profile YAML file.

    Raises
    ------
    ConfigError
        Neither a bundled name nor a readable, valid profile file (one line naming it).
    """
    from slamtrials.campaign.profilefile import is_profile_path, read_profile
    from slamtrials.sim.profiles import BUNDLED_PROFILES

    if value in BUNDLED_PROFILES:
        return BUNDLED_PROFILES[value]
    if is_profile_path(value) or Path(value).is_file():
        return read_profile(Path(value).expanduser())
    raise ConfigError(
        f"--profile: unknown profile {value!r}; bundled: {', '.join(sorted(BUNDLED_PROFILES))}, or a profile YAML file"
    )


def _dask_runner(scheduler: str | None, workers: int | None):
    """A :data:`~slamtrials.validation.Runner` that runs the replicas as Dask tasks."""
    from slamtrials.campaign.cluster import dask_client
    from slamtrials.validation import run_replica

    def run(plan: ValidationPlan, seeds: Sequence[int]) -> Iterable[ReplicaResult]:
        from distributed import as_completed

        with dask_client(scheduler, workers) as client:
            shared = client.scatter(plan, broadcast=True)
            futures = [client.submit(run_replica, shared, seed, pure=False) for seed in seeds]
            for future in as_completed(futures):
                yield future.result()

    return run


def validate(
    log: Annotated[Path, typer.Argument(help="The real log (CARMEN .clf/.log, .gz, .bz2, or a ROS bag).")],
    relations: Annotated[Path, typer.Option("--relations", "-r", help="The log's relations file (Freiburg form).")],
    profile: Annotated[
        str | None,
        typer.Option(
            "--profile",
            help="Error profile of the replicas: a bundled name or a profile YAML file; default: realistic, the "
            "default of every command.",
        ),
    ] = None,
    runs: Annotated[int, typer.Option("--runs", "-n", help="Number of replicas (seeds 0..N-1).")] = 5,
    algorithm: Annotated[
        str | None,
        typer.Option(
            "--algorithm",
            "-a",
            help="Registered SLAM algorithm (built-in: gmapping, karto, odometry); default gmapping.",
        ),
    ] = None,
    program: ProgramOpt = None,
    program_input: ProgramInputOpt = "carmen",
    program_output: ProgramOutputOpt = "tum",
    timeout: TimeoutOpt = 3600.0,
    preset: Annotated[str | None, typer.Option("--preset", "-p", help="Named parameter set of the algorithm.")] = None,
    settings: Annotated[
        list[str] | None, typer.Option("--set", help="Parameter override key=value (value read as YAML); repeatable.")
    ] = None,
    seed: Annotated[int, typer.Option("--seed", "-s", help="Seed of the reference SLAM run on the real log.")] = 0,
    tolerance: Annotated[
        float,
        typer.Option("--tolerance", help="Largest gap (s) between a relation timestamp and a frame (Freiburg: 0.1)."),
    ] = 0.1,
    json_out: Annotated[
        Path | None, typer.Option("--json", help="Write the numbers (real, simulated mean and std, per replica).")
    ] = None,
    figure: Annotated[
        Path | None,
        typer.Option("--figure", help="Write the figure (real vs simulated, per error kind): .png or .pdf."),
    ] = None,
    workers: Annotated[
        int, typer.Option("--workers", help="Replicas at a time: 1 runs them here, more on a local Dask cluster.")
    ] = 1,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler", help="Address (or scheduler file, .json) of a running Dask scheduler for the replicas."
        ),
    ] = None,
    split: Annotated[
        bool,
        typer.Option(
            "--split",
            help="Out of sample: calibrate on the first half of LOG (by time; odometry against that half's "
            "relations) and validate that profile on the second half. Not with --profile.",
        ),
    ] = False,
) -> None:
    """Replicate the real run LOG in the simulator and compare the algorithm's errors (paper, Section IV).

    The algorithm runs once on LOG (--seed): its final path and map are the replica's true path and
    world (unknown map cells are walls), recorded at the log's timestamps with the log's laser geometry
    and the profile's errors, --runs times (replica i has seed i). Every replica is scored on the real
    relations' time pairs with relations from its own ground truth; the raw odometry too. Prints the
    error profile (``profile: realistic`` by default) on stderr before the reference run.

    With --split the profile is fitted to the log's first half (``slamtrials calibrate --relations`` on
    the frames up to the middle of its time span and the relations within them), and the second half is
    validated with it as a log of its own: both are printed. With --program the first half's laser is
    fitted against the program's estimate and the map drawn from it.
    """
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from slamtrials.io.relations import read_relations
    from slamtrials.slam import get_algorithm, resolve_config
    from slamtrials.slamrun import load_recording
    from slamtrials.validation import ValidationSettings, check_belong
    from slamtrials.validation import validate as run_validation

    overrides = parse_settings(settings or [])
    spec = program_option(program, program_input, program_output, timeout)
    if spec is not None and (algorithm is not None or preset is not None or overrides):
        raise ConfigError("give --program or --algorithm (with --preset, --set), not both")
    algorithm = spec.label if spec is not None else (algorithm or "gmapping")
    options = ValidationSettings(
        algorithm=algorithm,
        preset=preset,
        overrides=overrides,
        program=spec,
        runs=runs,
        reference_seed=seed,
        tolerance=tolerance,
    )
    if workers < 1:
        raise ConfigError(f"--workers must be a positive integer, got {workers}")
    for path, what in ((json_out, "--json"), (figure, "--figure")):
        if path is not None and path.is_dir():
            raise ConfigError(f"{what} {path}: is a folder; give a file name")
    if figure is not None and figure.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise ConfigError(f"--figure {figure}: the name must end in .png, .pdf or .svg")
    if split and profile is not None:
        raise ConfigError("--split fits the profile to the log's first half; leave out --profile")
    from slamtrials.sim.profiles import DEFAULT_PROFILE

    chosen = resolve_profile_option(DEFAULT_PROFILE if profile is None else profile)
    if spec is not None:
        from slamtrials.external import check_program

        check_program(spec)  # fail before reading the log
    else:
        resolve_config(get_algorithm(algorithm), preset=preset, overrides=overrides)
    record = load_recording(log)
    rel = read_relations(relations)
    check_belong(record, rel, tolerance, log=str(log), relations_source=str(relations))
    halves = None
    if split:
        from slamtrials.validation.split import split_log

        halves = split_log(record, rel, log=str(log))  # a bad split fails before any work
    else:
        say_profile(chosen)
    runner = None
    if workers > 1 or scheduler is not None:
        quiet_dask()
        runner = _dask_runner(scheduler, workers)
    console = make_console()
    with Progress(
        TextColumn(f"{algorithm}: reference run, then replicas"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    ) as progress:
        task = progress.add_task("replicas", total=runs)
        if halves is None:
            result = run_validation(
                record,
                rel,
                chosen,
                options,
                runner=runner,
                on_replica=lambda _: progress.update(task, advance=1),
                log=str(log),
                relations_source=str(relations),
            )
        else:
            from slamtrials.calibration import CalibrationSettings
            from slamtrials.cli.calibrate import format_calibration, profile_name
            from slamtrials.validation.split import split_validate

            out_of_sample = split_validate(
                record,
                rel,
                options,
                CalibrationSettings(),
                profile_name=f"{profile_name(log)}-first-half",
                runner=runner,
                on_replica=lambda _: progress.update(task, advance=1),
                log=str(log),
                relations_source=str(relations),
            )
            result = out_of_sample.validation
            cut = halves.split_t
            console.print(
                f"first half (to {cut:.1f} s, {len(halves.first)} frames, {len(halves.first_relations)} relations): "
                "calibration",
                soft_wrap=True,
                highlight=False,
            )
            console.print(format_calibration(out_of_sample.calibration, f"{log} (first half)"), highlight=False)
            console.print(
                f"\nsecond half (from {cut:.1f} s, {len(halves.second)} frames, {len(halves.second_relations)} "
                "relations): validation with the first half's profile",
                soft_wrap=True,
                highlight=False,
            )
    console.print(format_validation(result), soft_wrap=True, highlight=False)
    written = []
    if json_out is not None:
        from slamtrials.atomicfile import atomic_write_text

        json_out.parent.mkdir(parents=True, exist_ok=True)
        written.append(atomic_write_text(json_out, json.dumps(result.to_dict(), indent=2) + "\n"))
    if figure is not None:
        written.append(write_figure(result, figure))
    if written:
        console.print(f"wrote {', '.join(str(p) for p in written)}", soft_wrap=True, highlight=False)


def format_validation(result: ValidationResult) -> str:
    """The paper's Tables II / III for one log: the real error and the replicas' mean and std, then per replica."""
    s = result.settings
    profile = result.profile.name
    seeds = f"seeds 0..{len(result.replicas) - 1}" if len(result.replicas) > 1 else "seed 0"
    lines = [
        f"{result.labels.get('log', 'log')}: {s.algorithm} (reference seed {s.reference_seed}), profile {profile}, "
        f"{len(result.replicas)} replicas ({seeds}), {result.frames} frames",
        f"relations: {result.relations_total} given, {result.real_slam.relations} matched on the real log, "
        f"{result.relations_replica} on replica frames",
    ]
    if result.blocked:
        lines.append(f"warning: {result.blocked} replica frames have the laser inside a wall of the reference map")
    w = max(10, len(s.algorithm))
    header = f"{'':<{w}} {'':<11} {'eps_t (m)':>10} {'s(eps_t)':>9}   {'eps_r (rad)':>11} {'s(eps_r)':>9}"
    lines += ["", header]
    for source in ("slam", "odometry"):
        name = s.algorithm if source == "slam" else "odometry"
        real = result.real(source)
        st, sr = result.simulated(source, "translational"), result.simulated(source, "rotational")
        lines.append(
            f"{name:<{w}} {'real log':<11} {fmt_number(real.translational, 4):>10} {'':>9}   "
            f"{fmt_number(real.rotational, 4):>11} {'':>9}"
        )
        lines.append(
            f"{'':<{w}} {'simulation':<11} {fmt_number(st.mean, 4):>10} {fmt_number(st.std, 4):>9}   "
            f"{fmt_number(sr.mean, 4):>11} {fmt_number(sr.std, 4):>9}"
        )
    lines += [
        "",
        f"{'seed':>4}  {'eps_t (m)':>10}  {'eps_r (rad)':>11}  {'odom eps_t':>10}  {'odom eps_r':>10}  {'updates':>7}  {'s':>6}",
    ]
    for r in result.replicas:
        lines.append(
            f"{r.seed:>4}  {fmt_number(r.slam.translational, 4):>10}  {fmt_number(r.slam.rotational, 4):>11}  "
            f"{fmt_number(r.odometry.translational, 4):>10}  {fmt_number(r.odometry.rotational, 4):>10}  "
            f"{r.updates:>7}  {r.seconds:6.1f}"
        )
    return "\n".join(lines)


def write_figure(result: ValidationResult, path: Path) -> Path:
    """Draw the real vs simulated errors (translational and rotational panels) and save it atomically."""
    from matplotlib.figure import Figure

    from slamtrials.atomicfile import atomic_write
    from slamtrials.report.validation_figure import ErrorBars, draw_real_vs_simulated

    fig = Figure(figsize=(8.0, 3.6))
    for k, (kind, unit) in enumerate((("translational", "m"), ("rotational", "rad"))):
        groups = []
        for source in ("slam", "odometry"):
            spread = result.simulated(source, kind)  # type: ignore[arg-type]
            groups.append(
                ErrorBars(
                    label=result.settings.algorithm if source == "slam" else "odometry",
                    real=result.real(source).value(kind),  # type: ignore[arg-type]
                    mean=spread.mean,
                    std=spread.std,
                    values=spread.values,
                )
            )
        draw_real_vs_simulated(
            fig.add_subplot(1, 2, k + 1),
            groups,
            unit=unit,
            title=f"{kind} error: real log vs {len(result.replicas)} replicas ({result.profile.name})",
        )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fmt = path.suffix.lower().lstrip(".")
    return atomic_write(path, lambda handle: fig.savefig(handle, format=fmt, dpi=150))


def register(app: typer.Typer) -> None:
    """Add the ``validate`` command to ``app``."""
    app.command("validate")(validate)
