"""One run of a campaign, as executed on a Dask worker: trial, evaluation, run folder.

:func:`run_one` takes a :class:`RunTask` (everything the run needs, small and picklable), loads the
world (cached per worker process), runs the trial (:func:`slamtrials.trial.run_trial`, or the injected
``trial_fn``), evaluates it (:func:`slamtrials.campaign.score.score_run`) and publishes the run folder
atomically (:func:`slamtrials.campaign.runfiles.publish_run`):

``run.json`` (written last), ``frames.npz``, ``estimate.tum``, ``map.yaml``/``map.pgm``/``map.png`` and
``relations.npz`` (the run's relation set). ``run.json`` also holds, under ``campaign``, the world, run
index, seed, ``eps_t``, ``eps_r``, their standard errors, the relation count, the scores of the online
estimate and the odometry on the same relations, and the metric settings, besides the trial's own
metadata (resolved trial config, termination reason, timings), its ``cost``
(:class:`~slamtrials.cost.RunCost`, which the catalog's ``details`` keep too) and its ``map_quality``
(the final map against the floor plan, :func:`slamtrials.campaign.mapscore.add_map_quality`; the
catalog's ``details`` keep its figures).

It returns a :class:`~slamtrials.campaign.results.RunDone` that the driver stores. Errors that are
properties of the run (a :class:`~slamtrials.errors.SlamtrialsError`, e.g. a start pose in a wall) come
back as a :class:`~slamtrials.campaign.results.RunFailed`; anything else (a bug, a lost worker)
propagates so that Dask retries it.
"""

from __future__ import annotations

import os
import socket
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from slamtrials.campaign.config import MetricSettings
from slamtrials.campaign.mapscore import add_map_quality
from slamtrials.campaign.results import RunDetails, RunDone, RunFailed, RunResult
from slamtrials.campaign.runfiles import publish_run, relative_run_folder
from slamtrials.campaign.score import RunScore, score_run
from slamtrials.campaign.worldset import load_world_cached
from slamtrials.cost import RunCost
from slamtrials.errors import SlamtrialsError
from slamtrials.metric.mapquality import MapQuality
from slamtrials.record import RunRecord
from slamtrials.trial import TrialConfig, TrialSummary
from slamtrials.trial.exploration import ExplorationMeasures
from slamtrials.worlds import World

__all__ = ["RunTask", "TrialFn", "run_one", "write_scored_run", "worker_name", "outcome", "failure"]

#: A trial: ``(world, config, seed) -> RunRecord`` with ``estimate`` [T, 3]; :func:`slamtrials.trial.run_trial` by default.
TrialFn = Callable[[World, TrialConfig, int], RunRecord]


@dataclass(frozen=True)
class RunTask:
    """Everything one run needs.

    Attributes
    ----------
    campaign:
        Absolute path of the campaign folder (shared by the driver and the workers).
    world, ref:
        The world's campaign name and what loads it (catalog name or absolute file).
    index, seed:
        Run index within the world (0-based) and the run's seed (:func:`slamtrials.campaign.seeds.run_seed`).
    trial:
        The trial's settings.
    metric:
        The relation sampling.
    trial_fn:
        The trial function; None means :func:`slamtrials.trial.run_trial`.
    extra:
        Facts added to ``run.json`` under ``campaign``.
    """

    campaign: str
    world: str
    ref: str
    index: int
    seed: int
    trial: TrialConfig
    metric: MetricSettings
    trial_fn: TrialFn | None = None
    extra: dict[str, Any] = field(default_factory=dict)


def worker_name() -> str:
    """``host:pid`` of the process running the task."""
    return f"{socket.gethostname()}:{os.getpid()}"


def write_scored_run(folder: Path, record: RunRecord, score: RunScore, *, frames_from: str | None = None) -> None:
    """Write the relation set, then the run folder (``run.json`` last) into ``folder``; ``frames_from``: the
    run folder holding the recorded frames (a replay's source; see :func:`slamtrials.io.runfolder.write_run`)."""
    from slamtrials.campaign.relationsetfile import write_relation_set
    from slamtrials.io.layout import RunFolder
    from slamtrials.io.runfolder import write_run

    write_relation_set(RunFolder(folder).relation_set, score.relation_set)
    write_run(folder, record, frames_from=frames_from)


def outcome(task_world: str, index: int, record: RunRecord, score: RunScore, started: float) -> RunDone:
    """What the driver stores for a done run."""
    trial = TrialSummary.of(record)
    cost = RunCost.of(record.metadata)
    exploration = ExplorationMeasures.of(record.metadata)
    quality = MapQuality.of(record.metadata)
    relation_set = score.relation_set
    return RunDone(
        world=task_world,
        index=index,
        eps_t=score.eps_t,
        eps_r=score.eps_r,
        relations=len(relation_set),
        termination=trial.termination_reason if trial else None,
        mapped_fraction=trial.mapped_fraction if trial else None,
        sim_duration=float(record.t[-1] - record.t[0]) if len(record) else 0.0,
        wall_time=time.perf_counter() - started,
        worker=worker_name(),
        folder=relative_run_folder(task_world, index),
        details=RunDetails(
            frames=len(record),
            distance_m=trial.distance_m if trial else None,
            observed_fraction=trial.observed_fraction if trial else None,
            slam_updates=trial.slam_updates if trial else None,
            relation_std_t=relation_set.std_t,
            relation_std_r=relation_set.std_r,
            relations_capped=bool(relation_set.capped),
            se_t=score.run.se_t,
            se_r=score.run.se_r,
            **(cost.figures() if cost is not None else {}),
            **(exploration.figures() if exploration is not None else {}),
            **(quality.figures() if quality is not None else {}),
        ),
    )


def failure(world: str, index: int, exc: BaseException) -> RunFailed:
    """The result of a run that failed for a reason of its own (not retried)."""
    return RunFailed(world=world, index=index, error=f"{type(exc).__name__}: {exc}", worker=worker_name())


def run_one(task: RunTask) -> RunResult:
    """Run, evaluate and store one run (see the module docstring); return what the driver records."""
    from slamtrials.trial import run_trial

    started = time.perf_counter()
    try:
        world = load_world_cached(task.ref)
        trial_fn = task.trial_fn or run_trial
        record = trial_fn(world, task.trial, task.seed)
        score = score_run(record, task.seed, task.metric)
        add_map_quality(record, world)
    except SlamtrialsError as exc:
        return failure(task.world, task.index, exc)
    record.metadata["campaign"] = {
        "world": task.world,
        "ref": task.ref,
        "index": task.index,
        "seed": task.seed,
        **score.to_dict(),
        "metric": task.metric.model_dump(mode="json"),
        **task.extra,
    }
    publish_run(task.campaign, task.world, task.index, lambda folder: write_scored_run(folder, record, score))
    return outcome(task.world, task.index, record, score, started)
