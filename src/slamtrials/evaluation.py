"""Evaluating trajectories with the localization error metric: the library behind ``slamtrials evaluate``.

Two forms:

* :func:`evaluate_files`: a real dataset. The estimate is a CARMEN log (its laser lines' first pose
  triple, or the second, at their ``ipc_timestamp``) or a TUM file; the relations file is
  ``t1 t2 x y z roll pitch yaw`` per line. An odometry log (a CARMEN log, whose laser lines' second
  triple is used, or a TUM file) carries a relation timestamp with no estimated pose within the
  tolerance to the nearest estimated pose.
* :func:`evaluate_run`: a simulated run folder. The estimate (a given estimate file, else the folder's
  ``estimate.tum``, else the run's odometry) is scored on the run's own relation set (``relations.npz``),
  or, for a folder without one or when asked, on relations sampled afresh from its ground truth (pilot,
  ``N = ceil(z^2 s^2 / d^2)``, N fresh pairs). Writes ``relations.txt`` and ``errors.npz`` into a new
  ``evaluations/<name>/`` folder of the run (or ``out``).

This module composes io (reading and writing files) and metric (pure computation), like the CLI does,
and does not print. The metric names bad relations or poses by index; this module maps an index back
to the file and line it came from (re-reading the file's data lines the way the readers count them).
"""

from __future__ import annotations

import io
import logging
import math
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

from slamtrials.errors import ConfigError, FormatError, MetricError
from slamtrials.metric.matching import DEFAULT_TOLERANCE, RUN_TOLERANCE
from slamtrials.metric.rule import SamplingRule
from slamtrials.record import Relations, Trajectory

logger = logging.getLogger(__name__)

__all__ = [
    "EvaluationResult",
    "PoseTriple",
    "Quantile",
    "evaluate_files",
    "evaluate_run",
    "read_estimate_file",
    "format_report",
    "FILE_TOLERANCE",
    "RUN_TOLERANCE",
]

#: Default matching tolerance (s) for dataset files: the Freiburg program's.
FILE_TOLERANCE = DEFAULT_TOLERANCE


class PoseTriple(str, Enum):
    """Which pose triple of a CARMEN laser line is the estimate.

    ``auto``: the second for a log whose laser lines hold no readings (a pose-only test log, written
    for the Freiburg metricEvaluator, which reads the second triple: FLASER ``odom_x odom_y odom_theta``,
    ROBOTLASER1 ``robot_pose``), else the first (slamtrials' own ``trajectory.clf``: the estimate first).
    """

    auto = "auto"
    first = "first"
    second = "second"


class Quantile(str, Enum):
    """Reference distribution of the critical value (the choices of :attr:`SamplingRule.distribution`)."""

    normal = "normal"
    t = "t"


# ----------------------------------------------------------------------------- reading, with line mapping


@dataclass(frozen=True)
class _Source:
    """A trajectory read from a file, and how to find the file line of its i-th pose."""

    trajectory: Trajectory
    path: Path
    kind: str  # "tum", "carmen", "carmen-odom" or "run"
    label: str
    line_name: str = ""  # CARMEN: the line type the poses came from (the laser kind read, or ODOM)

    def line_of(self, index: int) -> int | None:
        if self.kind == "tum":
            return _data_line(self.path, index)
        if self.kind in ("carmen", "carmen-odom"):
            return _data_line(self.path, index, lambda tokens: tokens[0] == self.line_name)
        return None


def _data_line(path: Path, index: int, keep=lambda tokens: True) -> int | None:
    """1-based line of the ``index``-th data line of ``path`` (as the readers count them), or None."""
    from slamtrials.io.textfile import data_lines, read_lines

    count = 0
    for number, tokens in data_lines(read_lines(path)):
        if keep(tokens):
            if count == index:
                return number
            count += 1
    return None


def _is_carmen(path: Path) -> bool:
    """A CARMEN log starts (after comments) with a message name; a TUM file with a number."""
    from slamtrials.io.compressed import read_head

    for line in read_head(path).decode("utf-8", errors="replace").split("\n"):
        tokens = line.split()
        if tokens and not tokens[0].startswith("#"):
            try:
                float(tokens[0])
            except ValueError:
                return True
            return False
    return False


def _read_trajectory(path: Path, triple: PoseTriple, what: str) -> _Source:
    """A CARMEN log (laser lines' first or second triple at their ipc_timestamp) or a TUM file.

    As odometry (``what == "odometry"``), a CARMEN log with ODOM lines gives its ODOM lines (the first of
    equal timestamps), as the Freiburg metricEvaluator takes them; without, its laser lines' second triple.
    """
    if _is_carmen(path):
        import numpy as np

        from slamtrials.io.carmen import read_carmen

        log = read_carmen(path, ranges=False)  # only the poses: any readings, beam counts or grids
        laser = log.laser
        if what == "odometry" and len(log.odom):
            first = np.concatenate([[True], np.diff(log.odom.t) > 0])
            label = f"{path} (CARMEN, {int(first.sum())} ODOM lines)"
            trajectory = Trajectory(t=log.odom.t[first], poses=log.odom.pose[first])
            return _Source(trajectory, path, "carmen-odom", label, "ODOM")
        pose_only = laser.pose_only
        if triple is PoseTriple.auto:
            triple = PoseTriple.second if pose_only else PoseTriple.first
            if what == "estimate" and pose_only:
                differ = int(np.count_nonzero((laser.pose != laser.odometry).any(axis=1)))
                if differ:
                    logger.warning(
                        "%s: the two pose triples differ on %d of %d pose-only %s lines: the second is evaluated, as the "
                        "Freiburg metricEvaluator does (--estimate-pose first for the other)",
                        path,
                        differ,
                        len(laser),
                        laser.kind,
                    )
        poses = laser.pose if triple is PoseTriple.first else laser.odometry
        label = f"{path} (CARMEN, {len(laser)} {laser.kind} lines, {triple.value} pose triple)"
        return _Source(Trajectory(t=laser.t, poses=poses), path, "carmen", label, laser.kind)
    from slamtrials.io.tum import read_tum

    trajectory = read_tum(path)
    return _Source(trajectory, path, "tum", f"{path} (TUM, {len(trajectory)} poses)")


def _shifted(source: _Source, time_offset: float) -> _Source:
    """``source`` with ``time_offset`` seconds subtracted from its times (another time base's origin)."""
    if not time_offset:
        return source
    if not math.isfinite(time_offset):
        raise ConfigError(f"--time-offset must be a finite number of seconds, got {time_offset}")
    moved = Trajectory(t=source.trajectory.t - float(time_offset), poses=source.trajectory.poses)
    label = f"{source.label}, times minus {time_offset:g} s"
    return _Source(moved, source.path, source.kind, label, source.line_name)


def read_estimate_file(path: str | Path, triple: PoseTriple = PoseTriple.auto) -> Trajectory:
    """An estimated trajectory from a TUM file or a CARMEN log (its laser lines' pose triple ``triple``:
    by default the first, or the second of a pose-only log, as ``slamtrials evaluate --estimate`` reads it).

    Raises
    ------
    FormatError
        The file does not parse (naming the line).
    """
    return _read_trajectory(Path(path), triple, "estimate").trajectory


def _check_belong(relations: Relations, relations_path: Path, sources: dict[str, _Source], tolerance: float) -> None:
    """Refuse relations none of whose timestamps is within ``tolerance`` of a pose of the estimate (or of
    the odometry): valid files that do not belong together, which would otherwise give an empty result."""
    import numpy as np

    from slamtrials.metric.matching import relations_meet

    stamps = np.concatenate([relations.t1, relations.t2])
    stamps = stamps[np.isfinite(stamps)]
    spans = []
    for source in sources.values():
        t = source.trajectory.t
        if len(t) == 0 or not (np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)):
            return  # the metric refuses such a trajectory, naming the line
        if len(stamps) == 0 or relations_meet(t, relations, tolerance):
            return
        spans.append(f"{source.path} has {len(t)} poses in [{float(t[0])!r}, {float(t[-1])!r}] s")
    where = f"[{float(stamps.min())!r}, {float(stamps.max())!r}] s" if len(stamps) else "no finite time"
    raise FormatError(
        relations_path,
        f"no relation timestamp ({len(relations)} relations in {where}) is within {tolerance:g} s of "
        f"a pose: {'; '.join(spans)}. These relations are not of this log",
    )


def _check_covers(source: _Source, run_t, run: Path, tolerance: float) -> None:
    """Refuse an estimate whose time span does not cover the run's: a trajectory of another run."""
    t = source.trajectory.t
    if len(t) == 0 or t[0] > run_t[0] + tolerance or t[-1] < run_t[-1] - tolerance:
        span = f"{float(t[0])!r} to {float(t[-1])!r} s" if len(t) else "no poses"
        shift = float(t[0] - run_t[0]) if len(t) else 0.0
        hint = ""
        if len(t) and abs(float(t[-1] - run_t[-1]) - shift) <= tolerance + 1e-9:
            hint = f" (or written in another time base: --time-offset {shift:g})"
        raise FormatError(
            source.path,
            f"its poses span {span} but the run {run} spans {float(run_t[0])!r} to {float(run_t[-1])!r} s: "
            f"not an estimate of this run{hint}",
        )


def _check_turns(source: _Source, odometry: Trajectory, run: Path) -> None:
    """Refuse an estimate whose turns are not the run's odometry's: a trajectory of another run that
    happens to cover this one's time span."""
    from slamtrials.metric.belongs import turn_agreement

    agreement = turn_agreement(source.trajectory, odometry)
    if not agreement.belongs:
        raise FormatError(
            source.path,
            f"its heading changes contradict the run {run}'s odometry in {agreement.contradicting_windows} of "
            f"{agreement.turning_windows} turning windows of 2 s: not an estimate of this run",
        )


def _with_lines(exc: MetricError, sources: dict[str, _Source], relations_path: Path | None) -> Exception:
    """Turn a MetricError that names an index into a FormatError that names the file and line."""
    if exc.what == "relations" and relations_path is not None and exc.index is not None:
        return FormatError(relations_path, exc.problem, line=_data_line(relations_path, exc.index))
    source = sources.get(exc.what or "")
    if source is not None and source.kind != "run":
        line = source.line_of(exc.index) if exc.index is not None else None
        return FormatError(source.path, exc.problem, line=line)
    if source is not None:
        return FormatError(source.path, exc.problem)
    return exc


# ----------------------------------------------------------------------------- the typed functions


@dataclass(frozen=True, eq=False)
class EvaluationResult:
    """What one evaluation produced.

    Attributes
    ----------
    relations:
        The relations evaluated (read or sampled).
    errors:
        Per-relation errors (:class:`~slamtrials.metric.relerrors.RelationErrors`).
    translational, rotational:
        :class:`~slamtrials.metric.summary.ErrorSummary` of each kind of error.
    estimate_label, relations_label:
        Where the estimate and the relations came from, for the report.
    tolerance:
        Matching tolerance (s).
    sampling:
        The :class:`~slamtrials.metric.sampling.SampledRelations` of a run folder, else None.
    relations_path:
        The relations file (read, or written into the run folder), for mapping relation indices to lines.
    written:
        Files written.
    """

    relations: Relations
    errors: object
    translational: object
    rotational: object
    estimate_label: str
    relations_label: str
    tolerance: float
    sampling: object = None
    relations_path: Path | None = None
    written: tuple[Path, ...] = ()


def _summaries(errors):
    from slamtrials.metric import summarize

    return summarize(errors.translational), summarize(errors.rotational)


def evaluate_files(
    estimate: Path,
    relations: Path,
    *,
    odometry: Path | None = None,
    estimate_pose: PoseTriple = PoseTriple.auto,
    tolerance: float = FILE_TOLERANCE,
    interpolate: bool = False,
    squared: bool = False,
    allow_outside: bool = False,
    time_offset: float = 0.0,
) -> EvaluationResult:
    """Evaluate an estimated trajectory file against a relations file (a real dataset).

    Parameters
    ----------
    estimate:
        CARMEN log or TUM file of the estimated trajectory.
    relations:
        Relations file, ``t1 t2 x y z roll pitch yaw`` per line.
    odometry:
        Optional CARMEN log (its ODOM lines, else the second pose triple of its laser lines) or TUM file
        used to carry relation timestamps without an estimated pose within ``tolerance`` to the nearest
        estimated pose.
    estimate_pose:
        Which pose triple of a CARMEN estimate to use (:class:`PoseTriple`; ``auto`` by default).
    tolerance, interpolate, squared, allow_outside:
        See :func:`slamtrials.metric.evaluate_relations`.
    time_offset:
        Seconds subtracted from the estimate's times (a program that wrote them in another time base,
        e.g. a bag exported from 1 s on).

    Raises
    ------
    FormatError
        A file that does not parse, data the metric refuses (naming the file and line), or relations
        none of whose timestamps is within ``tolerance`` of an estimated (or odometry) pose.
    """
    from slamtrials.io.relations import read_relations
    from slamtrials.metric import evaluate_relations

    estimate_source = _shifted(_read_trajectory(Path(estimate), estimate_pose, "estimate"), time_offset)
    sources = {"estimate": estimate_source}
    if odometry is not None:
        sources["odometry"] = _read_trajectory(Path(odometry), PoseTriple.second, "odometry")
    rel = read_relations(relations)
    _check_belong(rel, Path(relations), sources, tolerance)
    try:
        errors = evaluate_relations(
            estimate_source.trajectory,
            rel,
            tolerance=tolerance,
            interpolate=interpolate,
            odometry=sources["odometry"].trajectory if odometry is not None else None,
            squared=squared,
            allow_outside=allow_outside,
        )
    except MetricError as exc:
        raise _with_lines(exc, sources, Path(relations)) from None
    trans, rot = _summaries(errors)
    label = f"{relations} ({len(rel)} relations)"
    if odometry is not None:
        label += f", odometry {sources['odometry'].label}"
    return EvaluationResult(
        rel, errors, trans, rot, estimate_source.label, label, tolerance, relations_path=Path(relations)
    )


def evaluate_run(
    run: Path,
    *,
    estimate: Path | None = None,
    estimate_pose: PoseTriple = PoseTriple.auto,
    seed: int | None = None,
    rule: SamplingRule | None = None,
    tolerance: float = RUN_TOLERANCE,
    interpolate: bool = False,
    write: bool = True,
    out: Path | None = None,
    time_offset: float = 0.0,
) -> EvaluationResult:
    """Evaluate a run folder's estimate on the run's relation set, or on relations sampled from its truth.

    Parameters
    ----------
    run:
        A run folder (``frames.npz`` + ``run.json``).
    estimate:
        Estimate file (CARMEN or TUM) to evaluate instead of the folder's ``estimate.tum``; without
        either, the run's odometry is evaluated.
    estimate_pose:
        Which pose triple of a CARMEN estimate to use.
    seed, rule:
        Both None (the default): the run's own relation set (``relations.npz``, the relations its campaign
        or trial scored it on) when the folder has one. Otherwise relations are sampled afresh from the
        truth with ``seed`` (default 0) by ``rule`` (:class:`~slamtrials.metric.SamplingRule`, default
        the precise rule), sized on the evaluated estimate.
    tolerance, interpolate:
        Matching options. The run's odometry carries ground-truth timestamps without an
        estimated pose within ``tolerance`` (default 1 ms: the same frame) to the nearest estimated pose.
    write:
        Write ``errors.npz`` (and, for relations sampled afresh, ``relations.txt``): into ``out``, by
        default ``evaluations/<name>`` of the run (``<name>`` the estimate file's stem, ``estimate`` or
        ``odometry``), never over the run's own files (a campaign's relations stay as they were scored).
        Scored on the run's own relation set, the same estimate's folder is replaced (the relations are
        ``relations.npz``: no text copy); sampled afresh, a new folder ``<name>-2``, ``-3`` ... is made.
    out:
        Folder to write them into (created); it must not hold them already.
    time_offset:
        Seconds subtracted from an estimate file's times (``slamtrials export`` writes a simulated run's
        bag from 1 s on: an estimate in the bag's time base needs 1).

    Raises
    ------
    FormatError
        An unreadable run folder or estimate file, data the metric refuses, or an estimate file whose
        timestamps do not cover the run's or whose turns contradict the run's odometry (a trajectory of
        another run).
    ConfigError
        ``out`` already holds relations.
    """
    from slamtrials.campaign.relationsetfile import read_relation_set
    from slamtrials.io.errorsfile import write_errors
    from slamtrials.io.relations import write_relations
    from slamtrials.io.runfolder import RunFolder, read_run
    from slamtrials.metric import sample_relations, score_on_set

    run = Path(run)
    files = RunFolder(run)
    record = read_run(run)
    truth = Trajectory(t=record.t, poses=record.truth)
    odometry = Trajectory(t=record.t, poses=record.odometry)
    sources = {"truth": _Source(truth, files.frames, "run", "ground truth")}
    if estimate is None and files.estimate.is_file():
        estimate = files.estimate
    if estimate is not None:
        source = _shifted(_read_trajectory(Path(estimate), estimate_pose, "estimate"), time_offset)
        _check_covers(source, record.t, run, tolerance)
        _check_turns(source, odometry, run)
    elif record.estimate is not None:
        source = _Source(
            Trajectory(t=record.t, poses=record.estimate), files.frames, "run", f"{run} (the run's estimate)"
        )
    else:
        source = _Source(odometry, files.frames, "run", f"{run} (no SLAM estimate in the folder: the run's odometry)")
    sources["estimate"] = source
    sources["odometry"] = _Source(odometry, files.frames, "run", "odometry")
    stored = seed is None and rule is None and files.relation_set.is_file()
    sampled = None
    try:
        if stored:
            relation_set = read_relation_set(files.relation_set)
            scored = score_on_set(
                relation_set, truth, source.trajectory, tolerance=tolerance, odometry=odometry, what="estimate"
            )
            relations, errors = relation_set.relations(truth), scored.errors
            drawn = (
                f"the run's relation set {files.relation_set}: {len(relation_set)} relations, seed {relation_set.seed}, "
                f"{relation_set.rule.rule} rule"
            )
        else:
            sampled = sample_relations(
                truth,
                source.trajectory,
                rng=0 if seed is None else seed,
                rule=SamplingRule() if rule is None else rule,
                tolerance=tolerance,
                interpolate=interpolate,
                odometry=odometry,
            )
            relations, errors = sampled.relations, sampled.errors
            drawn = f"{len(relations)} relations sampled from the ground truth, seed {0 if seed is None else seed}"
    except MetricError as exc:
        raise _with_lines(exc, sources, None) from None
    written: tuple[Path, ...] = ()
    name = (
        Path(estimate).name.split(".")[0]
        if estimate is not None
        else ("estimate" if record.estimate is not None else "odometry")
    )
    name = name or "estimate"
    if out is not None:
        target = RunFolder(Path(out))
    elif stored:  # the result is a function of the estimate and the stored set: one folder per estimate
        target = RunFolder(files.evaluations / name)
    else:
        target = RunFolder(files.new_evaluation(name))
    relations_path = target.relations
    if write:
        if out is not None and (target.relations.exists() or target.errors.exists()):
            raise ConfigError(f"{target.path}: already holds an evaluation (errors.npz); choose another --out")
        if stored:  # the relations are the run's relations.npz: no text copy of them
            written = (write_errors(target.errors, relations, errors),)
        else:
            written = (
                write_relations(relations_path, relations),
                write_errors(target.errors, relations, errors),
            )
    trans, rot = _summaries(errors)
    as_text = write and not stored
    label = f"{relations_path} ({drawn})" if as_text else drawn
    return EvaluationResult(
        relations,
        errors,
        trans,
        rot,
        source.label,
        label,
        tolerance,
        sampled,
        relations_path if as_text else None,
        written,
    )


# ----------------------------------------------------------------------------- printing


def _row(summary) -> str:
    """``mean, std, min, max, n`` as the Freiburg metricEvaluator writes them (``%f, %f, %f, %f, %d``)."""
    return ", ".join(f"{v:f}" for v in summary.as_tuple()[:4]) + f", {summary.n}"


def format_report(result: EvaluationResult) -> str:
    """The text the command prints: sources, matching, sampling, and the two summaries."""
    from slamtrials.metric.summary import SUMMARY_HEADER

    errors = result.errors
    kind = "squared" if errors.squared else "absolute"
    unit_t, unit_r = errors.units
    out = io.StringIO()
    out.write(f"estimate:  {result.estimate_label}\n")
    out.write(f"relations: {result.relations_label}\n")
    out.write(
        f"matched {len(errors)} of {errors.n_relations} relations (nearest pose within {result.tolerance:g} s)"
        f", {len(errors.corrected)} through the odometry, {len(errors.unmatched)} unmatched\n"
    )
    if len(errors.unmatched):
        shown = errors.unmatched[:10].tolist()
        where = (
            [f"line {_data_line(result.relations_path, i)}" for i in shown]
            if result.relations_path
            else [f"#{i}" for i in shown]
        )
        more = f" and {len(errors.unmatched) - len(shown)} more" if len(errors.unmatched) > len(shown) else ""
        out.write(f"unmatched: {', '.join(where)}{more}\n")
    s = result.sampling
    if s is not None:
        out.write(
            f"sampling:  pilot {len(s.pilot_relations)} pairs, s_t = {s.std_t:.6g} {unit_t}, s_r = {s.std_r:.6g} {unit_r}; "
            f"z = {s.critical:.4f} ({s.rule.confidence:g} confidence, {s.rule.distribution}, {'two' if s.rule.sides == 2 else 'one'}-sided); "
            f"{s.rule.rule} rule, margins {s.margin_t:.3g} {unit_t}, {s.margin_r:.3g} {unit_r}"
            f"{f' ({s.rule.relative_margin:g} of the pilot means)' if s.rule.relative_margin is not None else ''} "
            f"-> N_t = {s.needed_t}, N_r = {s.needed_r}, N = {s.count}{' (capped)' if s.capped else ''}\n"
        )
    out.write(f"Translational error ({unit_t}, {kind}):\n{SUMMARY_HEADER}\n{_row(result.translational)}\n")
    out.write(f"Rotational error ({unit_r}, {kind}):\n{SUMMARY_HEADER}\n{_row(result.rotational)}\n")
    for path in result.written:
        out.write(f"wrote {path}\n")
    return out.getvalue()
