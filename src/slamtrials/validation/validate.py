"""The paper's Section IV as one function: a real run's error next to its simulated replicas' errors.

:func:`validate` takes a real log (a :class:`~slamtrials.record.RunRecord` whose ``t`` are the laser
timestamps) and its benchmark relations (Freiburg form, true relative poses at pairs of those times):

1. **reference**: the algorithm runs once on the log with ``reference_seed``; its final trajectory and
   map are the best estimate of what happened. Its error on the real relations (Freiburg matching:
   nearest pose within ``tolerance``) is the **real error**; the log's own odometry scored the same way is
   the real odometry's error.
2. **replica** (:mod:`slamtrials.validation.replica`): the reference map as the world, the reference
   trajectory as the true path, at the log's timestamps, with the log's laser geometry.
3. **replica runs**: replica ``i`` (``i = 0 .. runs-1``) uses seed ``i``: the simulator's stream is the
   first child of ``SeedSequence(i)``, SLAM's the second (:mod:`slamtrials.seeding`), as in a trial. It is
   recorded along the path with the profile's error models (:func:`~slamtrials.sim.pathreplay.simulate_path`)
   and the algorithm runs on it.
4. **scoring**: each real relation's ``(t1, t2)`` is mapped to the replica frames nearest in time (those
   within ``tolerance``; a relation whose two times fall on the same frame is left out); the replica's
   relations are the true motions between those frames (its own ground truth), and its SLAM estimate
   and its odometry are scored on them. Every replica is scored on the same frame pairs.

The errors are each run's mean over its relations (the paper's ``eps_t``, ``eps_r``); the simulated
errors are the mean and sample standard deviation over the replicas, as in the paper's Table III.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from slamtrials.errors import ConfigError
from slamtrials.metric.kernels import nearest_indices
from slamtrials.metric.matching import DEFAULT_TOLERANCE, RUN_TOLERANCE, relations_meet
from slamtrials.metric.relerrors import RelationErrors, evaluate_relations
from slamtrials.metric.sampling import relations_between
from slamtrials.record import Relations, RunRecord, Trajectory
from slamtrials.seeding import check_seed, run_streams
from slamtrials.sim.config import ErrorProfile, SimConfig
from slamtrials.sim.pathreplay import simulate_path
from slamtrials.sim.profiles import DEFAULT_PROFILE, resolve_profile
from slamtrials.slam.base import get_algorithm, resolve_config
from slamtrials.slam.offline import SlamRun
from slamtrials.slam.program import ProgramSpec
from slamtrials.validation.replica import UNKNOWN_AS_WALL, Replica, blocked_frames, laser_config_for, world_from_map

__all__ = [
    "ValidationSettings",
    "RunErrors",
    "ReplicaResult",
    "Spread",
    "ValidationPlan",
    "ValidationResult",
    "Runner",
    "check_belong",
    "frame_pairs",
    "replica_from_reference",
    "replica_config",
    "plan_validation",
    "run_replica",
    "validate",
    "SOURCES",
    "KINDS",
]

Source = Literal["slam", "odometry"]
Kind = Literal["translational", "rotational"]
#: What is scored: the SLAM estimate and the raw odometry.
SOURCES: tuple[Source, ...] = ("slam", "odometry")
#: The two error components (m, rad).
KINDS: tuple[Kind, ...] = ("translational", "rotational")


@dataclass(frozen=True)
class ValidationSettings:
    """What a validation runs.

    Attributes
    ----------
    algorithm, preset, overrides:
        The SLAM algorithm and its configuration (as ``slamtrials slam``); with ``program``, its label.
    program:
        An external SLAM program to validate instead of a registered algorithm.
    runs:
        Number of replicas (seeds ``0 .. runs-1``), at least 1.
    reference_seed:
        Seed of the reference SLAM run on the real log.
    tolerance:
        Largest gap (s) between a relation timestamp and a frame (the Freiburg program's 0.1 s).
    """

    algorithm: str = "gmapping"
    preset: str | None = None
    overrides: dict[str, Any] | None = None
    program: ProgramSpec | None = None
    runs: int = 5
    reference_seed: int = 0
    tolerance: float = DEFAULT_TOLERANCE

    def __post_init__(self) -> None:
        if isinstance(self.runs, bool) or not isinstance(self.runs, int) or self.runs < 1:
            raise ConfigError(f"--runs must be a positive integer, got {self.runs!r}")
        check_seed(self.reference_seed, "--seed")
        if not (math.isfinite(self.tolerance) and self.tolerance >= 0.0):
            raise ConfigError(f"--tolerance must be a non-negative number of seconds, got {self.tolerance!r}")


@dataclass(frozen=True)
class RunErrors:
    """One trajectory's errors: the means over its matched relations (m, rad) and how many matched."""

    translational: float
    rotational: float
    relations: int

    @classmethod
    def of(cls, errors: RelationErrors) -> RunErrors:
        if len(errors) == 0:
            return cls(math.nan, math.nan, 0)
        return cls(float(np.mean(errors.translational)), float(np.mean(errors.rotational)), len(errors))

    def value(self, kind: Kind) -> float:
        """The mean error of ``kind``."""
        return self.translational if kind == "translational" else self.rotational


@dataclass(frozen=True)
class ReplicaResult:
    """One replica run.

    Attributes
    ----------
    seed:
        The replica's seed (simulator and SLAM streams, :mod:`slamtrials.seeding`).
    slam, odometry:
        The SLAM estimate's and the simulated odometry's errors on the replica's relations.
    bias:
        The drawn odometry scale biases ``{"linear": m/m, "angular": rad/rad}``.
    updates:
        The algorithm's update count.
    seconds:
        Wall time of the replica (recording and SLAM, s).
    """

    seed: int
    slam: RunErrors
    odometry: RunErrors
    bias: dict[str, float]
    updates: int
    seconds: float

    def errors(self, source: Source) -> RunErrors:
        return self.slam if source == "slam" else self.odometry


@dataclass(frozen=True)
class Spread:
    """Mean and sample standard deviation (NaN for one value) of per-replica errors, with the values."""

    mean: float
    std: float
    values: tuple[float, ...]

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread:
        array = np.asarray(values, dtype=np.float64)
        std = float(np.std(array, ddof=1)) if len(array) > 1 else math.nan
        return cls(float(np.mean(array)), std, tuple(float(v) for v in array))


@dataclass(frozen=True, eq=False)
class ValidationPlan:
    """Everything a replica run needs (sent to workers as it is).

    Attributes
    ----------
    replica:
        World, path, times and laser geometry.
    config:
        The simulation config: the replica's laser geometry with the profile's error models.
    first, second:
        int64 ``[K]`` frame indices of the relations' two times.
    settings:
        Algorithm and seeds.
    """

    replica: Replica
    config: SimConfig
    first: NDArray[np.int64]
    second: NDArray[np.int64]
    settings: ValidationSettings

    def relations(self) -> Relations:
        """The replica's relations: the true motions between its frames ``first`` and ``second``."""
        return relations_between(Trajectory(t=self.replica.t, poses=self.replica.truth), self.first, self.second)


@dataclass(frozen=True, eq=False)
class ValidationResult:
    """The outcome of :func:`validate`.

    Attributes
    ----------
    settings:
        What was run.
    profile:
        The error profile of the replicas.
    real_slam, real_odometry:
        The reference SLAM run's and the log's odometry errors on the real relations.
    relations_total:
        Relations given.
    relations_replica:
        Relations the replicas are scored on (both times within the tolerance of a frame, on two frames).
    replicas:
        The replica runs, in seed order.
    frames:
        Frames of the log (and of every replica).
    blocked:
        Replica frames whose laser sits in a wall of the replica's world (scans of zeros).
    map_shape, map_resolution:
        The replica world's size (cells) and cell size (m): the reference map's.
    reference_updates:
        The reference run's update count.
    labels:
        ``log`` and ``relations_file``: where the inputs came from.
    """

    settings: ValidationSettings
    profile: ErrorProfile
    real_slam: RunErrors
    real_odometry: RunErrors
    relations_total: int
    relations_replica: int
    replicas: tuple[ReplicaResult, ...]
    frames: int
    blocked: int
    map_shape: tuple[int, int]
    map_resolution: float
    reference_updates: int
    labels: dict[str, str] = field(default_factory=dict)

    def real(self, source: Source) -> RunErrors:
        """The real log's errors of ``source``."""
        return self.real_slam if source == "slam" else self.real_odometry

    def simulated(self, source: Source, kind: Kind) -> Spread:
        """Mean and sample std over the replicas of the ``kind`` error of ``source``."""
        return Spread.of([r.errors(source).value(kind) for r in self.replicas])

    def to_dict(self) -> dict[str, Any]:
        """The numbers as a JSON-ready mapping (NaN as None): real, simulated mean and std, per replica."""

        def number(value: float) -> float | None:
            return value if math.isfinite(value) else None

        s = self.settings
        doc: dict[str, Any] = {
            "format": "slamtrials-validation/1",
            **self.labels,
            "algorithm": s.algorithm,
            "preset": s.preset,
            "overrides": s.overrides or {},
            "program": s.program.model_dump(mode="json") if s.program else None,
            "reference_seed": s.reference_seed,
            "tolerance_s": s.tolerance,
            "profile": self.profile.model_dump(mode="json"),
            "runs": len(self.replicas),
            "seeds": [r.seed for r in self.replicas],
            "frames": self.frames,
            "relations": {"given": self.relations_total, "replica": self.relations_replica},
            "replica_world": {
                "map_shape": list(self.map_shape),
                "resolution_m": self.map_resolution,
                "unknown_cells": "walls" if UNKNOWN_AS_WALL else "free",
                "blocked_frames": self.blocked,
            },
            "reference_updates": self.reference_updates,
        }
        for source in SOURCES:
            real = self.real(source)
            entry: dict[str, Any] = {"real_relations": real.relations}
            for kind in KINDS:
                spread = self.simulated(source, kind)
                unit = "m" if kind == "translational" else "rad"
                entry[f"{kind}_{unit}"] = {
                    "real": number(real.value(kind)),
                    "simulated_mean": number(spread.mean),
                    "simulated_std": number(spread.std),
                    "per_replica": [number(v) for v in spread.values],
                }
            doc[source] = entry
        doc["replicas"] = [
            {
                "seed": r.seed,
                "slam_translational_m": number(r.slam.translational),
                "slam_rotational_rad": number(r.slam.rotational),
                "odometry_translational_m": number(r.odometry.translational),
                "odometry_rotational_rad": number(r.odometry.rotational),
                "relations": r.slam.relations,
                "bias": r.bias,
                "updates": r.updates,
                "seconds": r.seconds,
            }
            for r in self.replicas
        ]
        return doc


#: How replicas are run: ``runner(plan, seeds)`` yields :func:`run_replica` ``(plan, seed)`` for each seed,
#: in any order (sequentially by default; the CLI passes one that uses Dask).
Runner = Callable[[ValidationPlan, Sequence[int]], Iterable[ReplicaResult]]


def _sequential(plan: ValidationPlan, seeds: Sequence[int]) -> Iterable[ReplicaResult]:
    for seed in seeds:
        yield run_replica(plan, seed)


def frame_pairs(
    t: NDArray[np.float64], relations: Relations, tolerance: float
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Frame indices ``[K]`` nearest to the relations' ``t1`` and ``t2`` (the earlier frame on a tie).

    Only relations whose two times are within ``tolerance`` (s) of a frame, and fall on two different
    frames, are kept, in their order.
    """
    first, _, near1 = nearest_indices(t, relations.t1, tolerance)
    second, _, near2 = nearest_indices(t, relations.t2, tolerance)
    keep = near1 & near2 & (first != second)
    return first[keep].astype(np.int64), second[keep].astype(np.int64)


def replica_from_reference(record: RunRecord, reference: SlamRun) -> Replica:
    """The replica of ``record``: ``reference``'s map as the world and its final trajectory as the path."""
    poses = reference.estimate_per_frame(record)
    world = world_from_map(reference.occupancy, name="replica", start=poses[0])
    laser = laser_config_for(record.laser, int(record.scans.shape[1]))
    return Replica(world=world, t=np.asarray(record.t, dtype=np.float64).copy(), truth=poses.copy(), laser=laser)


def replica_config(replica: Replica, profile: ErrorProfile) -> SimConfig:
    """The replica's simulation config: its laser geometry with ``profile``'s error models."""
    geometry = replica.laser.model_dump(include={"fov", "angular_resolution", "max_range", "min_range", "mount"})
    return SimConfig.from_dict({"profile": profile, "laser": geometry})


def plan_validation(
    replica: Replica, profile: ErrorProfile, relations: Relations, settings: ValidationSettings
) -> ValidationPlan:
    """The :class:`ValidationPlan` of ``replica`` for ``relations``.

    Raises
    ------
    ConfigError
        No relation falls on two frames of the replica.
    """
    first, second = frame_pairs(replica.t, relations, settings.tolerance)
    if len(first) == 0:
        raise ConfigError(
            f"no relation has both times within {settings.tolerance:g} s of two frames of the log; nothing to score"
        )
    return ValidationPlan(replica, replica_config(replica, profile), first, second, settings)


def run_replica(plan: ValidationPlan, seed: int) -> ReplicaResult:
    """Record replica ``seed`` along the plan's path, run the algorithm on it and score it."""
    s = plan.settings
    started = time.perf_counter()
    rng = np.random.default_rng(run_streams(seed).simulator)
    replica = plan.replica
    record = simulate_path(replica.world, replica.t, replica.truth, plan.config, rng)
    from slamtrials.external import run_offline

    slam = run_offline(record, s.algorithm, preset=s.preset, overrides=s.overrides, program=s.program, seed=seed)
    relations = plan.relations()
    estimate = evaluate_relations(slam.trajectory, relations, tolerance=RUN_TOLERANCE)
    odometry = evaluate_relations(Trajectory(t=record.t, poses=record.odometry), relations, tolerance=RUN_TOLERANCE)
    return ReplicaResult(
        seed=seed,
        slam=RunErrors.of(estimate),
        odometry=RunErrors.of(odometry),
        bias=dict(record.metadata["bias"]),
        updates=slam.updates,
        seconds=time.perf_counter() - started,
    )


def check_belong(record: RunRecord, relations: Relations, tolerance: float, *, log: str, relations_source: str) -> None:
    """Raise :class:`ConfigError` when no relation timestamp is within ``tolerance`` of a frame of ``record``."""
    if len(record) == 0:
        raise ConfigError(f"{log}: the log has no laser frames")
    if not relations_meet(record.t, relations, tolerance):
        stamps = np.concatenate([relations.t1, relations.t2])
        span = f"{np.nanmin(stamps):.3f} to {np.nanmax(stamps):.3f} s" if len(stamps) else "none"
        raise ConfigError(
            f"{relations_source} does not belong to {log}: no relation timestamp ({span}) is within "
            f"{tolerance:g} s of a laser frame ({record.t[0]:.3f} to {record.t[-1]:.3f} s)"
        )


def validate(
    record: RunRecord,
    relations: Relations,
    profile: ErrorProfile | str = DEFAULT_PROFILE,
    settings: ValidationSettings | None = None,
    *,
    reference: SlamRun | None = None,
    replica: Replica | None = None,
    runner: Runner | None = None,
    on_replica: Callable[[ReplicaResult], None] | None = None,
    log: str = "the log",
    relations_source: str = "the relations",
) -> ValidationResult:
    """Compare the algorithm's error on a real log with its error on ``settings.runs`` simulated replicas.

    Parameters
    ----------
    record:
        The real log (``t`` the laser timestamps the relations use; ``odometry`` the raw odometry).
    relations:
        The log's relations (true relative poses between pairs of its timestamps).
    profile:
        The replicas' error profile, or a bundled profile's name; by default
        :data:`~slamtrials.sim.profiles.DEFAULT_PROFILE` (``realistic``), the default of every simulation.
    settings:
        Algorithm, replica count, seeds, tolerance; ``ValidationSettings()`` by default.
    reference:
        The reference SLAM run on ``record``; by default the algorithm is run with ``reference_seed``.
    replica:
        The replica to record; by default built from the reference (:func:`replica_from_reference`). A test
        may give the true world and path of a simulated "real" run.
    runner:
        How replicas are run (:data:`Runner`); sequential by default.
    on_replica:
        Called with each replica's result as it finishes (for progress).
    log, relations_source:
        Names of the inputs, for messages and the JSON.

    Raises
    ------
    ConfigError
        Bad settings, an unknown profile name, a log without frames, relations that do not belong to the
        log (no timestamp near a frame), an unknown algorithm or parameter, or a reference run that gives
        nothing to replicate.
    """
    s = ValidationSettings() if settings is None else settings
    if not isinstance(profile, ErrorProfile):
        try:
            profile = resolve_profile(profile)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    check_belong(record, relations, s.tolerance, log=log, relations_source=relations_source)
    if s.program is None:
        resolve_config(get_algorithm(s.algorithm), preset=s.preset, overrides=s.overrides)
    if reference is None:
        from slamtrials.external import run_offline

        reference = run_offline(
            record, s.algorithm, preset=s.preset, overrides=s.overrides, program=s.program, seed=s.reference_seed
        )
    real_slam = RunErrors.of(
        evaluate_relations(reference.trajectory, relations, tolerance=s.tolerance, allow_outside=True)
    )
    odometry = Trajectory(t=record.t, poses=record.odometry)
    real_odometry = RunErrors.of(evaluate_relations(odometry, relations, tolerance=s.tolerance, allow_outside=True))
    if replica is None:
        replica = replica_from_reference(record, reference)
    plan = plan_validation(replica, profile, relations, s)
    done: dict[int, ReplicaResult] = {}
    for result in (runner or _sequential)(plan, list(range(s.runs))):
        done[result.seed] = result
        if on_replica is not None:
            on_replica(result)
    return ValidationResult(
        settings=s,
        profile=profile,
        real_slam=real_slam,
        real_odometry=real_odometry,
        relations_total=len(relations),
        relations_replica=len(plan.first),
        replicas=tuple(done[seed] for seed in sorted(done)),
        frames=len(record),
        blocked=blocked_frames(replica),
        map_shape=(replica.world.height, replica.world.width),
        map_resolution=replica.world.resolution,
        reference_updates=int(reference.updates),
        labels={"log": log, "relations_file": relations_source},
    )
