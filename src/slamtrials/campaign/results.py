"""What a campaign worker returns to the driver for one run: :class:`RunDone` or :class:`RunFailed`.

Both are small frozen dataclasses (Dask pickles them); the driver stores a :class:`RunDone` in the
catalog (:meth:`slamtrials.campaign.store.CampaignStore.record_done`), whose ``details`` column holds
:class:`RunDetails` as JSON.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RunDetails", "RunDone", "RunFailed", "RunResult"]


@dataclass(frozen=True)
class RunDetails:
    """Facts about a done run that the catalog keeps as JSON (the report reads them).

    Attributes
    ----------
    frames:
        Frames recorded.
    distance_m, observed_fraction, slam_updates:
        From the trial's summary (None for a record that no trial made).
    relation_std_t, relation_std_r:
        Standard deviations of the pilot relations' errors (m, rad).
    relations_capped:
        Whether the relation count hit the sampling rule's cap.
    se_t, se_r:
        Standard errors of ``eps_t`` (m) and ``eps_r`` (rad): the std of the per-relation errors over
        ``sqrt(N)`` (:func:`slamtrials.metric.standard_error`); None for runs stored by earlier versions.
    slam_cpu_s, slam_peak_mib, run_cpu_s, run_peak_mib, update_ms_median, update_ms_p90:
        What the run cost (:class:`~slamtrials.cost.RunCost`: CPU s, MiB, ms per update; not
        reproducible); None where not measured and for runs stored by earlier versions.
    final_coverage, time_to_90_s, distance_to_90_m, time_to_99_s, distance_to_99_m:
        How fast the run explored (:class:`~slamtrials.trial.exploration.ExplorationMeasures`: coverage
        0..1, simulated s and true path m to 90 % and 99 % coverage, None where not reached); all None for
        a record that no trial made and for runs stored by earlier versions.
    occupied_precision_1, occupied_recall_1, occupied_precision_2, occupied_recall_2, free_iou, ghost_free_m2:
        The final map against the floor plan (:class:`~slamtrials.metric.mapquality.MapQuality`: shares
        0..1, m^2); None for a run without a map and for runs stored by earlier versions.
    """

    frames: int
    distance_m: float | None
    observed_fraction: float | None
    slam_updates: int | None
    relation_std_t: float
    relation_std_r: float
    relations_capped: bool
    se_t: float | None = None
    se_r: float | None = None
    slam_cpu_s: float | None = None
    slam_peak_mib: float | None = None
    run_cpu_s: float | None = None
    run_peak_mib: float | None = None
    update_ms_median: float | None = None
    update_ms_p90: float | None = None
    final_coverage: float | None = None
    time_to_90_s: float | None = None
    distance_to_90_m: float | None = None
    time_to_99_s: float | None = None
    distance_to_99_m: float | None = None
    occupied_precision_1: float | None = None
    occupied_recall_1: float | None = None
    occupied_precision_2: float | None = None
    occupied_recall_2: float | None = None
    free_iou: float | None = None
    ghost_free_m2: float | None = None


@dataclass(frozen=True)
class RunDone:
    """A run that was simulated (or replayed), evaluated and published.

    Attributes
    ----------
    world, index:
        The run's world and index.
    eps_t, eps_r:
        Mean translational (m) and rotational (rad) error over its relations.
    relations:
        Relations it was scored on.
    termination, mapped_fraction:
        The trial's termination reason and mapped fraction (None for a record that no trial made).
    sim_duration, wall_time:
        Simulated duration and wall time of the task (s).
    worker:
        ``host:pid`` of the worker.
    folder:
        Run folder, relative to the campaign folder.
    details:
        Further facts (:class:`RunDetails`).
    """

    world: str
    index: int
    eps_t: float
    eps_r: float
    relations: int
    termination: str | None
    mapped_fraction: float | None
    sim_duration: float
    wall_time: float
    worker: str
    folder: str
    details: RunDetails


@dataclass(frozen=True)
class RunFailed:
    """A run that failed for a reason of its own (a bad world, a metric that cannot score it), or was lost.

    Attributes
    ----------
    world, index:
        The run's world and index.
    error:
        ``ExceptionType: message``.
    worker:
        ``host:pid`` of the worker, if known.
    """

    world: str
    index: int
    error: str
    worker: str | None = None


#: What :func:`slamtrials.campaign.task.run_one` and the replay's worker function return.
RunResult = RunDone | RunFailed
