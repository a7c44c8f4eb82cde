"""``slamtrials evaluate``: the localization error of a trajectory, as the Freiburg evaluation program reports it.

A thin wrapper over :mod:`slamtrials.evaluation` (see there for the two forms, dataset files and RUN
folders); prints ``Mean, Std, Min, Max, NumMeasures`` of the translational (m) and rotational (rad)
errors (``%f`` fixed-point, six decimals, as the Freiburg metricEvaluator's ``-e`` file) and can write the per-relation errors (``--errors FILE``: ``.npz``, or a text table otherwise).
"""

from __future__ import annotations

from dataclasses import replace
from enum import Enum
from pathlib import Path
from typing import Annotated

import typer
from pydantic import ValidationError

from slamtrials.errors import ConfigError
from slamtrials.evaluation import FILE_TOLERANCE, RUN_TOLERANCE, PoseTriple, Quantile
from slamtrials.metric.rule import SamplingRule

__all__ = ["evaluate", "register"]


class RuleChoice(str, Enum):
    """The named sampling rules (:attr:`SamplingRule.rule`)."""

    precise = "precise"
    paper = "paper"


def evaluate(
    run: Annotated[
        Path | None,
        typer.Argument(
            help="Simulated run folder: evaluate its estimate on the run's relation set (or on relations sampled afresh from its ground truth)."
        ),
    ] = None,
    estimate: Annotated[
        Path | None, typer.Option("--estimate", "-e", help="Estimated trajectory: CARMEN log or TUM file.")
    ] = None,
    relations: Annotated[
        Path | None,
        typer.Option("--relations", "-r", help="Relations file 't1 t2 x y z roll pitch yaw' (real datasets)."),
    ] = None,
    odometry: Annotated[
        Path | None,
        typer.Option(
            "--odometry",
            help="CARMEN log (its ODOM lines, else its laser lines' second triple, as the Freiburg program takes them) or TUM file whose odometry carries unmatched relation timestamps to the nearest estimated pose.",
        ),
    ] = None,
    estimate_pose: Annotated[
        PoseTriple,
        typer.Option(
            "--estimate-pose",
            help="Pose triple of a CARMEN estimate: first (laser pose, e.g. SLAM-corrected; slamtrials' trajectory.clf) or second (raw odometry; what the Freiburg metricEvaluator reads). auto: second for a pose-only log (FLASER 0 lines, a Freiburg-style test log), else first.",
        ),
    ] = PoseTriple.auto,
    time_offset: Annotated[
        float,
        typer.Option(
            "--time-offset",
            help="Seconds subtracted from the estimate's times: an estimate written in another time base (a bag from 'slamtrials export' of a simulated run starts at 1 s: --time-offset 1).",
        ),
    ] = 0.0,
    tolerance: Annotated[
        float | None,
        typer.Option(
            "--tolerance",
            help="Largest gap (s) between a relation timestamp and the matched pose, inclusive. Default: 0.1 (the Freiburg program's) for files; 0.001 for a RUN, whose estimate shares the simulator's clock, so that a ground-truth pose between two estimated poses is reached through the odometry rather than given a neighbour's pose. inf: the nearest pose whatever the gap (the Freiburg program without -o).",
        ),
    ] = None,
    interpolate: Annotated[
        bool, typer.Option("--interpolate", help="Interpolate between the poses around each relation timestamp.")
    ] = False,
    squared: Annotated[
        bool, typer.Option("--squared", help="Report squared errors (m^2, rad^2) instead of absolute ones.")
    ] = False,
    allow_outside: Annotated[
        bool,
        typer.Option(
            "--allow-outside",
            help="Report relations outside the estimate's time span as unmatched instead of refusing them.",
        ),
    ] = False,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            help="RUN: folder for errors.npz, and relations.txt for relations sampled afresh (default: RUN/evaluations/<name>/; the run's own files are never overwritten).",
        ),
    ] = None,
    errors_out: Annotated[
        Path | None, typer.Option("--errors", help="Write per-relation errors here (.npz, or a text table).")
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option(
            "--seed",
            "-s",
            help="RUN: sample relations afresh with this seed instead of scoring on the run's own relation set (relations.npz).",
        ),
    ] = None,
    rule: Annotated[
        RuleChoice | None,
        typer.Option(
            "--rule",
            help="RUN: sample afresh by this rule: precise (margin relative to the error; the default) or paper (absolute margins).",
        ),
    ] = None,
    pilot: Annotated[int | None, typer.Option("--pilot", help="Pilot pairs of the sampling (RUN).")] = None,
    confidence: Annotated[
        float | None, typer.Option("--confidence", help="Confidence level of the margins (RUN).")
    ] = None,
    relative_margin: Annotated[
        float | None,
        typer.Option(
            "--relative-margin", help="Margin of error as a fraction of the pilot's mean error (precise rule, RUN)."
        ),
    ] = None,
    margin_t: Annotated[
        float | None,
        typer.Option("--margin-t", help="Margin of error of the mean translational error, m (paper rule, RUN)."),
    ] = None,
    margin_r: Annotated[
        float | None,
        typer.Option("--margin-r", help="Margin of error of the mean rotational error, rad (paper rule, RUN)."),
    ] = None,
    distribution: Annotated[
        Quantile | None,
        typer.Option(
            "--distribution",
            help="Critical value: normal or Student t with pilot-1 degrees of freedom (RUN).",
        ),
    ] = None,
    sides: Annotated[
        int | None, typer.Option("--sides", help="2 for a two-sided quantile, 1 for one-sided (RUN).")
    ] = None,
) -> None:
    """Localization error (Kuemmerle et al.) of an estimate: Mean, Std, Min, Max, NumMeasures in m and rad."""
    from slamtrials.evaluation import evaluate_files, evaluate_run, format_report
    from slamtrials.io.errorsfile import write_errors

    if tolerance is None:
        tolerance = RUN_TOLERANCE if run is not None else FILE_TOLERANCE
    if not (tolerance >= 0):
        raise ConfigError(f"--tolerance must be a non-negative number of seconds, got {tolerance}")
    if run is not None:
        if relations is not None or odometry is not None:
            raise ConfigError(
                "with a RUN folder, relations are sampled from its ground truth and its odometry is used: drop --relations and --odometry"
            )
        if seed is not None and seed < 0:
            raise ConfigError(f"--seed must be a non-negative integer, got {seed}")
        given = {
            "rule": rule.value if rule is not None else None,
            "pilot": pilot,
            "confidence": confidence,
            "relative_margin": relative_margin,
            "margin_t": margin_t,
            "margin_r": margin_r,
            "distribution": distribution.value if distribution is not None else None,
            "sides": sides,
            "squared": squared or None,
        }
        given = {name: value for name, value in given.items() if value is not None}
        result = evaluate_run(
            run,
            estimate=estimate,
            estimate_pose=estimate_pose,
            seed=seed,
            rule=sampling_rule(**given) if given else None,
            tolerance=tolerance,
            interpolate=interpolate,
            out=out,
            time_offset=time_offset,
        )
    else:
        if out is not None:
            raise ConfigError("--out is for a RUN folder's sampled relations: drop it, or use --errors FILE")
        if estimate is None or relations is None:
            raise ConfigError("give a RUN folder, or both --estimate FILE and --relations FILE")
        result = evaluate_files(
            estimate,
            relations,
            odometry=odometry,
            estimate_pose=estimate_pose,
            tolerance=tolerance,
            interpolate=interpolate,
            squared=squared,
            allow_outside=allow_outside,
            time_offset=time_offset,
        )
    if errors_out is not None:
        written = write_errors(errors_out, result.relations, result.errors)
        result = replace(result, written=(*result.written, written))
    typer.echo(format_report(result), nl=False)


def sampling_rule(**values: object) -> SamplingRule:
    """The rule of the command's options; a bad value is a one-line ConfigError naming the option."""
    try:
        return SamplingRule.model_validate(values)
    except ValidationError as exc:
        problems = "; ".join(
            f"--{'-'.join(str(p) for p in e['loc']).replace('_', '-')} = {e['input']!r}: {e['msg']}"
            for e in exc.errors()
        )
        raise ConfigError(problems) from None


def register(app: typer.Typer) -> None:
    """Add the ``evaluate`` command to ``app``."""
    app.command("evaluate")(evaluate)
