"""Out-of-sample validation: calibrate on one half of a real log, validate on the other.

A profile fitted to a log and validated on the same log is checked against the data it was fitted to.
:func:`split_validate` cuts the log at the middle of its time span: the first half (its frames and the
relations whose two times both lie in it) is calibrated (:mod:`slamtrials.calibration`), and the profile
it gives is validated on the second half (:func:`~slamtrials.validation.validate.validate`), a log of
its own with its own reference run. The second half's replicas never saw the data they are judged on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials.calibration import (
    Calibration,
    CalibrationSettings,
    Reference,
    calibrate,
    check_calibratable,
    slam_reference,
)
from slamtrials.errors import CalibrationError, ConfigError
from slamtrials.record import Relations, RunRecord
from slamtrials.sim.config import ErrorProfile
from slamtrials.slam.program import ProgramSpec
from slamtrials.validation.validate import (
    ReplicaResult,
    Runner,
    ValidationResult,
    ValidationSettings,
    check_belong,
    validate,
)

__all__ = [
    "LogHalves",
    "SplitValidation",
    "program_reference",
    "split_log",
    "record_frames",
    "relations_within",
    "split_validate",
]

#: Fewest relations a half must hold: fewer give no usable mean error.
MIN_RELATIONS = 20


def record_frames(record: RunRecord, keep: NDArray[np.bool_]) -> RunRecord:
    """The frames of ``record`` where ``keep`` (bool ``[T]``) holds, as a record of their own (same laser and
    metadata; the SLAM results of the whole record are not carried over)."""
    return RunRecord(
        t=record.t[keep].copy(),
        scans=record.scans[keep].copy(),
        odometry=record.odometry[keep].copy(),
        truth=record.truth[keep].copy(),
        stalled=record.stalled[keep].copy(),
        laser=record.laser,
        metadata=dict(record.metadata),
    )


def relations_within(relations: Relations, start: float, end: float) -> Relations:
    """The relations whose two times both lie in ``[start, end]`` (s)."""
    inside = (relations.t1 >= start) & (relations.t1 <= end) & (relations.t2 >= start) & (relations.t2 <= end)
    return Relations(t1=relations.t1[inside], t2=relations.t2[inside], delta=relations.delta[inside])


@dataclass(frozen=True, eq=False)
class LogHalves:
    """A log cut in two at ``split_t`` (s): the frames up to it and after it, each with the relations whose
    two times lie within its frames' span."""

    split_t: float
    first: RunRecord
    second: RunRecord
    first_relations: Relations
    second_relations: Relations


def split_log(
    record: RunRecord, relations: Relations, *, min_relations: int = MIN_RELATIONS, log: str = "the log"
) -> LogHalves:
    """Cut ``record`` at the middle of its time span; each half keeps the relations inside its frames' span.

    Raises
    ------
    ConfigError
        A half with fewer than ``min_relations`` relations (the message gives both counts), or a log of
        fewer than two frames.
    """
    if len(record) < 2:
        raise ConfigError(f"{log}: a split needs a log of at least two frames, got {len(record)}")
    split_t = 0.5 * (float(record.t[0]) + float(record.t[-1]))
    early = record.t <= split_t
    first, second = record_frames(record, early), record_frames(record, ~early)
    first_relations = relations_within(relations, float(first.t[0]), float(first.t[-1]))
    second_relations = relations_within(relations, float(second.t[0]), float(second.t[-1]))
    counts = (len(first_relations), len(second_relations))
    if min(counts) < min_relations:
        raise ConfigError(
            f"{log}: cut at {split_t:.1f} s, the first half holds {counts[0]} relations and the second {counts[1]}; "
            f"a split needs at least {min_relations} in each (relations that span the cut belong to neither)"
        )
    return LogHalves(split_t, first, second, first_relations, second_relations)


@dataclass(frozen=True, eq=False)
class SplitValidation:
    """What :func:`split_validate` found: the halves, the first half's calibration and profile, and the
    second half's validation with that profile."""

    halves: LogHalves
    calibration: Calibration
    profile: ErrorProfile
    validation: ValidationResult


def program_reference(record: RunRecord, program: ProgramSpec, seed: int) -> Reference:
    """An external program's reference over ``record``: its estimate at every frame, and the map drawn
    from that estimate (:func:`~slamtrials.slam.estimatemap.map_of_estimate`, as for any program)."""
    from slamtrials.external import run_offline

    run = run_offline(record, program.label, program=program, seed=seed)
    source = f"{program.label} estimate (seed {seed}) and the map drawn from it"
    return Reference.from_grid(run.estimate_per_frame(record), run.occupancy, source)


def split_validate(
    record: RunRecord,
    relations: Relations,
    settings: ValidationSettings | None = None,
    calibration_settings: CalibrationSettings | None = None,
    *,
    profile_name: str = "first-half",
    runner: Runner | None = None,
    on_replica: Callable[[ReplicaResult], None] | None = None,
    log: str = "the log",
    relations_source: str = "the relations",
) -> SplitValidation:
    """Calibrate on the first half of ``record`` (by time) and validate the fitted profile on the second.

    The first half's laser is fitted against ``settings.algorithm`` (or ``settings.program``: its
    estimate and the map drawn from it, :func:`program_reference`) run over it with
    ``settings.reference_seed`` (the same algorithm, settings and seed that give the real error on the
    second half), its odometry against its own relations (``calibrate --relations``); the calibration's
    bootstrap uses that seed too.

    Raises
    ------
    ConfigError
        A half with too few relations (:func:`split_log`), bad settings, relations that do not belong to
        the log.
    CalibrationError
        The first half is too short or too still to calibrate from (the message says which half).
    ProgramError
        ``settings.program`` fails on the first half.
    """
    s = ValidationSettings() if settings is None else settings
    cal = CalibrationSettings() if calibration_settings is None else calibration_settings
    check_belong(record, relations, s.tolerance, log=log, relations_source=relations_source)
    halves = split_log(record, relations, log=log)
    try:
        check_calibratable(
            halves.first, min_frames=cal.min_frames, min_distance=cal.min_distance, min_rotation=cal.min_rotation
        )
    except CalibrationError as exc:
        raise CalibrationError(f"{log}, first half (to {halves.split_t:.1f} s): {exc}") from None
    if s.program is None:
        reference = slam_reference(
            halves.first, s.algorithm, preset=s.preset, overrides=s.overrides, seed=s.reference_seed
        )
    else:
        reference = program_reference(halves.first, s.program, s.reference_seed)
    try:
        calibration = calibrate(
            halves.first,
            reference,
            cal,
            seed=s.reference_seed,
            relations=halves.first_relations,
            relations_source=f"{relations_source} (first half)",
        )
    except CalibrationError as exc:
        raise CalibrationError(f"{log}, first half (to {halves.split_t:.1f} s): {exc}") from None
    profile = calibration.profile(
        profile_name,
        f"fitted by slamtrials validate --split to the first half of {log} (to {halves.split_t:.1f} s): the laser "
        f"against {reference.source}, the odometry against the half's {len(halves.first_relations)} relations",
    )
    validation = validate(
        halves.second,
        halves.second_relations,
        profile,
        s,
        runner=runner,
        on_replica=on_replica,
        log=f"{log} (second half)",
        relations_source=relations_source,
    )
    return SplitValidation(halves, calibration, profile, validation)
