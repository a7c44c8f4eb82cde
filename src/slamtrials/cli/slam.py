"""``slamtrials slam``: run a SLAM algorithm over a run folder, CARMEN log or ROS bag and write its outputs.

A thin wrapper over :mod:`slamtrials.slamrun` (see there for the output files). ``--set key=value``
values are read as YAML (``--set resolution=0.1``, ``--set initial_pose=[1, 2, 0]``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

import typer

from slamtrials.cli.common import make_console, quiet_dask
from slamtrials.cli.costtext import run_cost_text
from slamtrials.errors import ConfigError

if TYPE_CHECKING:
    from slamtrials.repeat import RepeatedSlam
    from slamtrials.slam.program import ProgramSpec

__all__ = ["slam", "register", "parse_settings", "format_repeat", "program_option"]


ProgramOpt = Annotated[
    str | None,
    typer.Option(
        "--program",
        help="Instead of --algorithm: a SLAM program, as a shell command with {input} and {output} "
        "(and optionally {seed}, {workdir}).",
    ),
]
ProgramInputOpt = Annotated[
    str, typer.Option("--program-input", help="Format the program reads: carmen, bag (ROS 1) or bag2 (ROS 2).")
]
ProgramOutputOpt = Annotated[
    str, typer.Option("--program-output", help="Format of the trajectory the program writes: tum or carmen.")
]
TimeoutOpt = Annotated[
    float, typer.Option("--timeout", help="Seconds the program may run on one recording before it is killed.")
]


def program_option(command: str | None, input_format: str, output_format: str, timeout: float) -> ProgramSpec | None:
    """The :class:`~slamtrials.slam.program.ProgramSpec` of the ``--program`` options (None without ``--program``)."""
    if command is None:
        return None
    from slamtrials.slam.program import program_spec

    return program_spec(command=command, input=input_format, output=output_format, timeout=timeout)


def parse_settings(settings: list[str]) -> dict[str, Any]:
    """``["key=value", ...]`` as a dict, each value parsed with ``yaml.safe_load``.

    Raises
    ------
    ConfigError
        An item without ``=`` or a key, or a value that is not YAML.
    """
    import yaml

    values: dict[str, Any] = {}
    for item in settings:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(f"--set expects key=value, got {item!r}")
        try:
            values[key] = yaml.safe_load(text) if text.strip() else None
        except yaml.YAMLError as exc:
            problem = str(exc).splitlines()[0]
            raise ConfigError(f"--set {key}: {text!r} is not a YAML value ({problem})") from None
    return values


def slam(
    input_: Annotated[
        Path, typer.Option("--input", "-i", help="Run folder, CARMEN log (.clf/.log, .gz, .bz2) or ROS bag.")
    ],
    out: Annotated[
        Path,
        typer.Option("--out", "-o", help="Folder for trajectory.tum/.clf, map.yaml/.pgm/.png, timing.csv, slam.json."),
    ],
    algorithm: Annotated[
        str | None,
        typer.Option("--algorithm", "-a", help="Registered SLAM algorithm (built-in: gmapping, karto, odometry)."),
    ] = None,
    program: ProgramOpt = None,
    program_input: ProgramInputOpt = "carmen",
    program_output: ProgramOutputOpt = "tum",
    timeout: TimeoutOpt = 3600.0,
    preset: Annotated[str | None, typer.Option("--preset", "-p", help="Named parameter set of the algorithm.")] = None,
    settings: Annotated[
        list[str] | None, typer.Option("--set", help="Parameter override key=value (value read as YAML); repeatable.")
    ] = None,
    seed: Annotated[int, typer.Option("--seed", "-s", help="Seed of the algorithm's random draws.")] = 0,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace SLAM outputs already in --out.")] = False,
    runs: Annotated[
        str | None,
        typer.Option(
            "--runs",
            help="Repeat with seeds 0..N-1 (N >= 2), or 'auto' for the paper's Section III-C rule; needs --relations.",
        ),
    ] = None,
    relations: Annotated[
        Path | None,
        typer.Option("--relations", "-r", help="The dataset's relations file; with --runs every run is scored on it."),
    ] = None,
    confidence: Annotated[
        float, typer.Option("--confidence", help="Confidence level of the interval of the mean (and of --runs auto).")
    ] = 0.95,
    margin_t: Annotated[
        float, typer.Option("--margin-t", help="--runs auto: margin of the mean translational error (m).")
    ] = 0.02,
    margin_r: Annotated[
        float, typer.Option("--margin-r", help="--runs auto: margin of the mean rotational error (rad).")
    ] = 0.02,
    max_runs: Annotated[int, typer.Option("--max-runs", help="--runs auto: cap on the runs.")] = 60,
    tolerance: Annotated[
        float,
        typer.Option(
            "--tolerance", help="Largest gap (s) between a relation timestamp and a frame (the Freiburg program's 0.1)."
        ),
    ] = 0.1,
    workers: Annotated[
        int | None, typer.Option("--workers", help="Local Dask workers for --runs (default: one per core).")
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option("--scheduler", help="Address (or scheduler file, .json) of a running Dask scheduler for --runs."),
    ] = None,
) -> None:
    """Run a SLAM algorithm (--algorithm) or program (--program) over a recording and write its
    trajectory and map; on a run folder, print its error on the run's relation set.

    A program gets the recording with odometry and laser only (no ground truth), in the run's time
    base, and writes its trajectory; a program that fails, times out or writes nothing is one line and
    exit status 2. With --runs N and --relations R: run it N times (seeds 0..N-1, in parallel), score
    each run on the dataset's relations, and print and write the per-run errors, their mean, sample
    std, Student t interval and the share of runs that diverged, with a figure of the sorted errors
    and the best and worst run's maps.
    """
    from slamtrials.slamrun import SLAM_FILE

    if (algorithm is None) == (program is None):
        raise ConfigError("give either --algorithm NAME or --program COMMAND")
    spec = program_option(program, program_input, program_output, timeout)
    if spec is not None and (preset is not None or settings):
        raise ConfigError("--preset and --set configure an --algorithm; a --program is configured in its command")
    if runs is not None or relations is not None:
        if runs is None or relations is None:
            raise ConfigError("--runs and --relations go together: give both to repeat SLAM on a dataset")
        _repeat(
            algorithm,
            spec,
            input_,
            out,
            preset,
            parse_settings(settings or []),
            runs,
            relations,
            confidence=confidence,
            margin_t=margin_t,
            margin_r=margin_r,
            max_runs=max_runs,
            tolerance=tolerance,
            workers=workers,
            scheduler=scheduler,
            overwrite=overwrite,
        )
        return
    if seed < 0:
        raise ConfigError(f"--seed must be a non-negative integer, got {seed}")
    if (out / SLAM_FILE).exists() and not overwrite:
        raise ConfigError(f"{out}: already holds SLAM outputs; choose another --out or pass --overwrite")
    if spec is not None:
        _run_program(spec, input_, out, seed, overwrite)
    else:
        assert algorithm is not None
        _run_algorithm(algorithm, input_, out, preset, parse_settings(settings or []), seed, overwrite)
    _print_score(input_, out)


def _run_algorithm(
    algorithm: str, input_: Path, out: Path, preset: str | None, overrides: dict[str, Any], seed: int, overwrite: bool
) -> None:
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from slamtrials.slam import get_algorithm, resolve_config
    from slamtrials.slamrun import load_recording, run_slam, write_slam_outputs

    resolve_config(get_algorithm(algorithm), preset=preset, overrides=overrides)  # fail before reading the input
    record = load_recording(input_)
    console = make_console()
    columns = (TextColumn(f"{algorithm}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        task = progress.add_task("slam", total=len(record))
        result = run_slam(
            record,
            algorithm,
            preset=preset,
            overrides=overrides,
            seed=seed,
            source=str(input_),
            on_frame=lambda k, total: progress.update(task, completed=k + 1),
        )
    written = write_slam_outputs(result, out, overwrite=overwrite)
    mean_ms = 1000.0 * float(result.timing.mean())
    names = ", ".join(p.name for p in written)
    console.print(
        f"{out}: {len(record)} frames, {result.updates} updates, {mean_ms:.2f} ms per frame; wrote {names}",
        soft_wrap=True,
        highlight=False,
    )
    console.print(run_cost_text(result.cost), soft_wrap=True, highlight=False)


def _run_program(spec: ProgramSpec, input_: Path, out: Path, seed: int, overwrite: bool) -> None:
    from slamtrials.external import check_program, run_program
    from slamtrials.slamrun import load_recording, write_program_outputs

    check_program(spec)  # before reading the input
    record = load_recording(input_)
    console = make_console()
    with console.status(f"{spec.label} on {len(record)} frames", spinner="dots") if console.is_terminal else _nothing():
        run = run_program(record, spec, seed)
    written = write_program_outputs(run, record, out, source=str(input_), overwrite=overwrite)
    a = run.alignment
    console.print(
        f"{out}: {spec.label} ran {run.seconds:.1f} s on {len(record)} frames and wrote {a.poses_read} poses "
        f"({a.frames_at_pose} at a frame, {a.frames_carried} frames carried by odometry); "
        f"wrote {', '.join(p.name for p in written)}",
        soft_wrap=True,
        highlight=False,
    )
    console.print(run_cost_text(run.cost), soft_wrap=True, highlight=False)


def _nothing():
    from contextlib import nullcontext

    return nullcontext()


def _print_score(input_: Path, out: Path) -> None:
    """On a simulated run folder: the estimate's error on the run's relation set (nothing written)."""
    from slamtrials.evaluation import evaluate_run
    from slamtrials.io.runfolder import RunFolder

    if not (input_.is_dir() and RunFolder(input_).is_complete()):
        return
    result = evaluate_run(input_, estimate=out / "trajectory.tum", write=False)
    t, r = result.translational, result.rotational
    make_console().print(
        f"error: eps_t {t.mean:.6f} m, eps_r {r.mean:.6f} rad on {result.relations_label}",
        soft_wrap=True,
        highlight=False,
    )


def _repeat(
    algorithm: str | None,
    program: ProgramSpec | None,
    input_: Path,
    out: Path,
    preset: str | None,
    overrides: dict[str, Any],
    runs: str,
    relations: Path,
    *,
    confidence: float,
    margin_t: float,
    margin_r: float,
    max_runs: int,
    tolerance: float,
    workers: int | None,
    scheduler: str | None,
    overwrite: bool,
) -> None:
    """``slam --runs``: SLAM repeated on a dataset (:func:`slamtrials.repeat.repeat_slam`)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    from slamtrials.io.relations import read_relations
    from slamtrials.repeat import RepeatSettings, repeat_slam, write_repeat_outputs
    from slamtrials.slam import get_algorithm, resolve_config
    from slamtrials.slamrun import load_recording

    count: int | Literal["auto"] = "auto" if runs.strip().lower() == "auto" else _int_option("--runs", runs)
    label = program.label if program is not None else str(algorithm)
    settings = RepeatSettings(
        algorithm=label,
        program=program,
        preset=preset,
        overrides=overrides,
        runs=count,
        confidence=confidence,
        margin_t=margin_t,
        margin_r=margin_r,
        max_runs=max_runs,
        tolerance=tolerance,
    )
    if (out / "summary.json").exists() and not overwrite:
        raise ConfigError(f"{out}: already holds a repeated experiment; choose another --out or pass --overwrite")
    if program is not None:
        from slamtrials.external import check_program

        check_program(program)  # fail before reading the input
    else:
        resolve_config(get_algorithm(label), preset=preset, overrides=overrides)
    record = load_recording(input_)
    rel = read_relations(relations)
    console = make_console()
    quiet_dask()
    planned = settings.initial if count == "auto" else int(count)
    with Progress(
        TextColumn(f"{label} runs"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    ) as progress:
        task = progress.add_task("runs", total=planned)
        result = repeat_slam(
            record,
            rel,
            settings,
            scheduler=scheduler,
            workers=workers,
            source=str(input_),
            relations_source=str(relations),
            on_run=lambda run, total: progress.update(task, advance=1, total=total),
        )
    written = write_repeat_outputs(result, out, overwrite=overwrite)
    console.print(format_repeat(result), soft_wrap=True, highlight=False)
    console.print(f"wrote {', '.join(p.name for p in written)} to {out}", soft_wrap=True, highlight=False)


def _int_option(name: str, text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ConfigError(f"{name} must be an integer of at least 2 or 'auto', got {text!r}") from None


def format_repeat(result: RepeatedSlam) -> str:
    """The per-run table and the summary of a repeated experiment (six decimals, as the Freiburg tool); CPU s
    and MiB: the SLAM algorithm's (or program's) CPU time and peak memory in the run (:class:`~slamtrials.cost.RunCost`)."""
    lines = [
        f"{'seed':>4}  {'eps_t (m)':>10}  {'eps_r (rad)':>11}  {'relations':>9}  {'updates':>7}  {'seconds':>7}  "
        f"{'CPU s':>7}  {'MiB':>6}"
    ]
    flagged = dict(zip((r.seed for r in result.runs), result.diverged.diverged.tolist()))
    for r in result.runs:
        cpu = r.cost.slam_cpu_s if r.cost is not None else None
        mib = r.cost.slam_peak_mib if r.cost is not None else None
        lines.append(
            f"{r.seed:>4}  {r.eps_t:10.6f}  {r.eps_r:11.6f}  {r.relations:>9}  {r.updates:>7}  {r.seconds:7.1f}  "
            f"{'-' if cpu is None else f'{cpu:.1f}':>7}  {'-' if mib is None else f'{mib:.0f}':>6}"
            + ("  diverged" if flagged[r.seed] else "")
        )
    st, sr, level = result.stats_t, result.stats_r, f"{100 * result.settings.confidence:g} %"
    it, ir = result.interval_t, result.interval_r
    lines.append(
        f"translational: mean {st.mean:.6f} m, std {st.std_sample:.6f} m, {level} interval of the mean "
        f"[{it.low:.6f}, {it.high:.6f}] ({it.method}, {st.n} runs)"
    )
    lines.append(
        f"rotational:    mean {sr.mean:.6f} rad, std {sr.std_sample:.6f} rad, {level} interval "
        f"[{ir.low:.6f}, {ir.high:.6f}]" + ("" if ir.method == it.method else f" ({ir.method})")
    )
    d = result.diverged
    lines.append(
        f"diverged: {int(d.diverged.sum())} of {len(result.runs)} runs ({100 * d.share:.0f} %) above "
        f"{d.factor:g} x median = {d.threshold:.6f} m; best seed {result.best.seed} ({result.best.eps_t:.6f} m), "
        f"worst seed {result.worst.seed} ({result.worst.eps_t:.6f} m)"
    )
    for seed, error in result.failed:
        lines.append(f"failed: seed {seed}: {error}")
    if result.rule:
        lines.append(result.rule)
    return "\n".join(lines)


def register(app: typer.Typer) -> None:
    """Add the ``slam`` command to ``app``."""
    app.command("slam")(slam)
