"""SLAM repeated on a dataset: one recording, many seeds, the spread of the errors (``slamtrials slam --runs``).

One run of a particle filter on a real log is luck, the paper's point applied to datasets: the same
algorithm with another seed may map the building well or diverge. :func:`repeat_slam` runs an algorithm
over one recording with seeds ``0 .. N-1`` (in parallel on a Dask cluster, a local one by default, as
campaigns do), scores every run against the dataset's relations (the Kuemmerle et al. metric, as
``slamtrials evaluate --estimate --relations`` does), and reduces the per-run mean errors to their mean,
sample standard deviation, a Student t confidence interval of the mean and the share of runs that
diverged (error above 5 times the median). ``runs="auto"`` lets the paper's Section III-C rule choose
the run count: 10 runs, then as many as ``N = z^2 s^2 / d^2`` asks for, up to a cap.

:func:`write_repeat_outputs` writes ``runs.csv`` (one line per seed, with what it cost: SLAM CPU time,
peak memory and time per update, :class:`~slamtrials.cost.RunCost`), ``summary.json``, the sorted
per-run errors as a figure (the paper's Fig. 1 for a dataset) and the maps of the best and worst runs.
This module composes io, slam, metric, campaign (the Dask client) and report, like the CLI; it does not print.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from slamtrials.atomicfile import atomic_write, atomic_write_text
from slamtrials.cost import COST_FIGURES, RunCost
from slamtrials.errors import ConfigError, MetricError, ProgramError
from slamtrials.metric.divergence import DEFAULT_DIVERGENCE_FACTOR, Divergence, divergence
from slamtrials.metric.matching import DEFAULT_TOLERANCE, relations_meet
from slamtrials.metric.meaninterval import MeanInterval, positive_mean_interval
from slamtrials.metric.relerrors import evaluate_relations
from slamtrials.metric.runcount import runs_needed
from slamtrials.metric.stats import EnvironmentStats, environment_stats
from slamtrials.record import OccupancyGrid, Relations, RunRecord, Trajectory
from slamtrials.slam.offline import run_over_recording
from slamtrials.slam.program import ProgramSpec

__all__ = [
    "RepeatSettings",
    "RepeatedRun",
    "RepeatedSlam",
    "repeat_slam",
    "write_repeat_outputs",
    "check_relations_fit",
    "REPEAT_FILES",
]

#: Files :func:`write_repeat_outputs` writes (``summary.json`` last).
REPEAT_FILES = (
    "runs.csv",
    "errors.png",
    "best_map.png",
    "best_map.yaml",
    "best_map.pgm",
    "worst_map.png",
    "worst_map.yaml",
    "worst_map.pgm",
    "summary.json",
)


@dataclass(frozen=True)
class RepeatSettings:
    """How a repeated experiment is run and summarized.

    Attributes
    ----------
    algorithm, preset, overrides:
        The SLAM algorithm and its configuration (as ``slamtrials slam``); with ``program``, its label.
    program:
        An external SLAM program to run instead of a registered algorithm (given ``{seed}``).
    runs:
        Number of runs (seeds ``0 .. runs-1``), or ``"auto"`` for the paper's Section III-C rule.
    confidence:
        Confidence level of the interval of the mean (and of the run-count rule).
    margin_t, margin_r:
        Margins (m, rad) of the run-count rule, for ``runs="auto"``.
    initial, max_runs:
        First batch and cap of the run-count rule, for ``runs="auto"``.
    tolerance:
        Matching tolerance of relation timestamps to the recording's (s).
    divergence_factor:
        A run diverged when its mean translational error is above this many times the median.
    """

    algorithm: str
    preset: str | None = None
    overrides: dict[str, Any] | None = None
    program: ProgramSpec | None = None
    runs: int | Literal["auto"] = 10
    confidence: float = 0.95
    margin_t: float = 0.02
    margin_r: float = 0.02
    initial: int = 10
    max_runs: int = 60
    tolerance: float = DEFAULT_TOLERANCE
    divergence_factor: float = DEFAULT_DIVERGENCE_FACTOR

    def __post_init__(self) -> None:
        if self.runs != "auto" and (isinstance(self.runs, bool) or not isinstance(self.runs, int) or self.runs < 2):
            raise ConfigError(f"--runs must be an integer of at least 2 or 'auto', got {self.runs!r}")
        if not 0.0 < self.confidence < 1.0:
            raise ConfigError(f"confidence must be between 0 and 1, got {self.confidence}")
        if not (self.margin_t > 0.0 and self.margin_r > 0.0):
            raise ConfigError(f"margins must be positive, got {self.margin_t} m and {self.margin_r} rad")
        if not 2 <= self.initial <= self.max_runs:
            raise ConfigError(f"need 2 <= initial <= max_runs, got {self.initial} and {self.max_runs}")
        if not self.tolerance >= 0.0:
            raise ConfigError(f"tolerance must be a non-negative number of seconds, got {self.tolerance}")
        if not self.divergence_factor > 1.0:
            raise ConfigError(f"the divergence factor must be above 1, got {self.divergence_factor}")


@dataclass(frozen=True, eq=False)
class RepeatedRun:
    """One run of the repeated experiment.

    Attributes
    ----------
    seed:
        The run's seed (the algorithm's stream as in :mod:`slamtrials.seeding`).
    eps_t, eps_r:
        Mean translational (m) and rotational (rad) error over the matched relations.
    relations:
        Relations matched.
    updates:
        The algorithm's update count.
    seconds:
        Wall time of the algorithm (s).
    occupancy:
        The final map.
    cost:
        CPU time and peak memory of the algorithm (or the program's process) and time per update.
    """

    seed: int
    eps_t: float
    eps_r: float
    relations: int
    updates: int
    seconds: float
    occupancy: OccupancyGrid
    cost: RunCost | None = None


@dataclass(frozen=True, eq=False)
class RepeatedSlam:
    """The outcome of :func:`repeat_slam`.

    Attributes
    ----------
    settings:
        What was run.
    runs:
        The runs, in seed order.
    stats_t, stats_r:
        Mean, sample std and Student t interval of the per-run errors (m, rad).
    interval_t, interval_r:
        The interval of the mean error that is printed: the Student t one, or a bootstrap one where that
        reaches below zero (:func:`~slamtrials.metric.meaninterval.positive_mean_interval`).
    diverged:
        The runs whose translational error is above ``divergence_factor`` times the median.
    rule:
        For ``runs="auto"``: the run-count rule's last decision, as text; else empty.
    source:
        Where the recording came from.
    relations_source:
        Where the relations came from.
    failed:
        ``(seed, error)`` of the runs whose program failed (an external program only), in seed order;
        the statistics are over the other runs.
    """

    settings: RepeatSettings
    runs: tuple[RepeatedRun, ...]
    stats_t: EnvironmentStats
    stats_r: EnvironmentStats
    interval_t: MeanInterval
    interval_r: MeanInterval
    diverged: Divergence
    rule: str
    source: str
    relations_source: str
    failed: tuple[tuple[int, str], ...] = ()

    @property
    def best(self) -> RepeatedRun:
        """The run with the lowest translational error (the lowest seed among equal ones)."""
        return min(self.runs, key=lambda run: (run.eps_t, run.seed))

    @property
    def worst(self) -> RepeatedRun:
        """The run with the highest translational error (the lowest seed among equal ones)."""
        return max(self.runs, key=lambda run: (run.eps_t, -run.seed))


def check_relations_fit(
    record: RunRecord,
    relations: Relations,
    tolerance: float,
    *,
    source: str = "the recording",
    relations_source: str = "the relations",
) -> None:
    """Raise :class:`ConfigError` when no relation timestamp is within ``tolerance`` of a frame of ``record``.

    Valid files that do not belong together (a log and another dataset's relations) would otherwise give
    an empty or meaningless result.
    """
    if not relations_meet(record.t, relations, tolerance):
        stamps = np.concatenate([relations.t1, relations.t2])
        span = f"{np.nanmin(stamps):.3f} to {np.nanmax(stamps):.3f} s" if len(stamps) else "none"
        raise ConfigError(
            f"{relations_source} and {source} do not belong together: no relation timestamp ({span}) "
            f"is within {tolerance:g} s of a frame ({record.t[0]:.3f} to {record.t[-1]:.3f} s)"
        )


def _one_run(record: RunRecord, relations: Relations, settings: RepeatSettings, seed: int) -> RepeatedRun:
    """Run the algorithm with one seed and score it (on a Dask worker)."""
    s = settings
    started = time.perf_counter()
    if s.program is not None:
        from slamtrials.external import run_program

        ran = run_program(record, s.program, seed)
        trajectory, updates, occupancy, cost = (
            Trajectory(t=record.t, poses=ran.estimate),
            ran.alignment.poses_read,
            ran.occupancy,
            ran.cost,
        )
    else:
        result = run_over_recording(record, s.algorithm, preset=s.preset, overrides=s.overrides, seed=seed)
        trajectory, updates, occupancy, cost = result.trajectory, result.updates, result.occupancy, result.cost
    seconds = time.perf_counter() - started
    errors = evaluate_relations(trajectory, relations, tolerance=s.tolerance, allow_outside=True)
    if len(errors) == 0:
        raise MetricError(f"seed {seed}: no relation matched a pose of the estimate within {s.tolerance:g} s")
    return RepeatedRun(
        seed=seed,
        eps_t=float(np.mean(errors.translational)),
        eps_r=float(np.mean(errors.rotational)),
        relations=len(errors),
        updates=updates,
        seconds=seconds,
        occupancy=occupancy,
        cost=cost,
    )


def repeat_slam(
    record: RunRecord,
    relations: Relations,
    settings: RepeatSettings,
    *,
    scheduler: Any = None,
    workers: int | None = None,
    on_run: Callable[[RepeatedRun, int], None] | None = None,
    source: str = "",
    relations_source: str = "",
) -> RepeatedSlam:
    """Run ``settings.algorithm`` over ``record`` with seeds ``0, 1, ...`` and score each run on ``relations``.

    Parameters
    ----------
    record:
        The recording (a real log read as a run record; ``t`` holds the laser timestamps the relations use).
    relations:
        The dataset's relations (``t1``, ``t2`` at laser timestamps, true relative poses).
    settings:
        Algorithm, run count and statistics (:class:`RepeatSettings`).
    scheduler, workers:
        A Dask scheduler address or client, or the number of local workers (default: one per core).
    on_run:
        Called as ``on_run(run, planned)`` in the driver as each run finishes (for progress).
    source, relations_source:
        Where the recording and the relations came from (for messages and ``summary.json``).

    Raises
    ------
    ConfigError
        Bad settings, a recording without frames, or relations that do not belong to the recording.
    """
    from distributed import as_completed

    from slamtrials.campaign.cluster import dask_client
    from slamtrials.slam import get_algorithm, resolve_config

    if len(record) == 0:
        raise ConfigError(f"{source or 'the recording'} has no frames")
    if settings.program is None:
        resolve_config(get_algorithm(settings.algorithm), preset=settings.preset, overrides=settings.overrides)
    check_relations_fit(
        record,
        relations,
        settings.tolerance,
        source=source or "the recording",
        relations_source=relations_source or "the relations",
    )
    done: dict[int, RepeatedRun] = {}
    failed: dict[int, str] = {}
    rule = ""
    with dask_client(scheduler, workers) as client:
        shared = client.scatter(record, broadcast=True)

        def run_seeds(seeds: range, planned: int) -> None:
            futures = {client.submit(_one_run, shared, relations, settings, seed, pure=False): seed for seed in seeds}
            for future in as_completed(futures):
                try:
                    run = future.result()
                except ProgramError as exc:  # the program failed on this run: a failed run, not a failed command
                    failed[futures[future]] = str(exc)
                    continue
                done[run.seed] = run
                if on_run is not None:
                    on_run(run, planned)

        if settings.runs == "auto":
            planned = settings.initial
            while True:
                run_seeds(range(len(done), planned), planned)
                ordered = [done[s] for s in sorted(done)]
                decision = runs_needed(
                    [r.eps_t for r in ordered],
                    [r.eps_r for r in ordered],
                    margin_t=settings.margin_t,
                    margin_r=settings.margin_r,
                    confidence=settings.confidence,
                    distribution="t",
                    min_runs=settings.initial,
                    max_runs=settings.max_runs,
                )
                rule = (
                    f"Section III-C rule: {decision.done} runs done, N_t = {decision.needed_t}, N_r = {decision.needed_r} "
                    f"(margins {settings.margin_t:g} m, {settings.margin_r:g} rad at {100 * settings.confidence:g} %, Student t)"
                    + ("; capped" if decision.capped else "")
                )
                if decision.enough or decision.needed <= len(done):
                    break
                planned = decision.needed
        else:
            run_seeds(range(settings.runs), settings.runs)
    if len(done) < 2:
        first = min(failed) if failed else None
        why = f"; seed {first}: {failed[first]}" if first is not None else ""
        raise ProgramError(f"only {len(done)} of {len(done) + len(failed)} runs finished, too few for statistics{why}")
    runs = tuple(done[s] for s in sorted(done))
    eps_t = [r.eps_t for r in runs]
    eps_r = [r.eps_r for r in runs]
    stats_t = environment_stats(eps_t, confidence=settings.confidence, distribution="t")
    stats_r = environment_stats(eps_r, confidence=settings.confidence, distribution="t")
    return RepeatedSlam(
        settings=settings,
        runs=runs,
        stats_t=stats_t,
        stats_r=stats_r,
        interval_t=positive_mean_interval(eps_t, stats_t),
        interval_r=positive_mean_interval(eps_r, stats_r),
        diverged=divergence(eps_t, settings.divergence_factor),
        rule=rule,
        source=source,
        relations_source=relations_source,
        failed=tuple(sorted(failed.items())),
    )


def write_repeat_outputs(result: RepeatedSlam, out_dir: str | Path, *, overwrite: bool = False) -> list[Path]:
    """Write :data:`REPEAT_FILES` into ``out_dir`` (created if needed); return the paths written.

    Raises
    ------
    ConfigError
        ``out_dir`` already holds a repeated experiment (``summary.json``) and ``overwrite`` is False.
    """
    from matplotlib.figure import Figure

    from slamtrials.io.mapfile import write_map, write_map_png
    from slamtrials.report.dataset_figures import draw_repeated_errors

    out = Path(out_dir)
    if (out / "summary.json").exists() and not overwrite:
        raise ConfigError(f"{out}: already holds a repeated experiment; choose another --out or pass --overwrite")
    out.mkdir(parents=True, exist_ok=True)
    diverged = dict(zip((r.seed for r in result.runs), result.diverged.diverged.tolist()))
    lines = [f"seed,eps_t,eps_r,relations,updates,seconds,diverged,{','.join(COST_COLUMNS)}\n"]
    lines += [
        f"{r.seed},{r.eps_t!r},{r.eps_r!r},{r.relations},{r.updates},{r.seconds:.3f},{int(diverged[r.seed])},"
        f"{_cost_cells(r.cost)}\n"
        for r in result.runs
    ]
    written = [atomic_write_text(out / "runs.csv", "".join(lines))]
    fig = Figure(figsize=(7.0, 3.6))
    draw_repeated_errors(
        fig.add_subplot(1, 1, 1),
        [r.eps_t for r in result.runs],
        result.diverged.threshold,
        factor=result.diverged.factor,
        title=f"{result.settings.algorithm}: {len(result.runs)} runs of {Path(result.source).name or 'the recording'}",
    )
    fig.tight_layout()
    written.append(atomic_write(out / "errors.png", lambda handle: fig.savefig(handle, format="png", dpi=150)))
    for name, run in (("best", result.best), ("worst", result.worst)):
        grid = run.occupancy
        written.append(write_map_png(out / f"{name}_map.png", grid.grid))
        written.append(write_map(out / f"{name}_map.yaml", grid.grid, grid.resolution, grid.origin))
        written.append(out / f"{name}_map.pgm")
    summary = {
        "algorithm": result.settings.algorithm,
        "preset": result.settings.preset,
        "overrides": result.settings.overrides or {},
        "program": result.settings.program.model_dump(mode="json") if result.settings.program else None,
        "input": result.source,
        "relations": result.relations_source,
        "runs": len(result.runs),
        "seeds": [r.seed for r in result.runs],
        "failed": [{"seed": seed, "error": error} for seed, error in result.failed],
        "run_count_rule": result.rule,
        "confidence": result.settings.confidence,
        "translational_m": _stats_json(result.stats_t, result.interval_t),
        "rotational_rad": _stats_json(result.stats_r, result.interval_r),
        "diverged": {
            "threshold_m": result.diverged.threshold,
            "factor": result.diverged.factor,
            "share": result.diverged.share,
            "seeds": [r.seed for r, d in zip(result.runs, result.diverged.diverged) if d],
        },
        "cost": _mean_cost(result.runs),
        "best": {"seed": result.best.seed, "eps_t": result.best.eps_t},
        "worst": {"seed": result.worst.seed, "eps_t": result.worst.eps_t},
    }
    written.append(atomic_write_text(out / "summary.json", json.dumps(summary, indent=2) + "\n"))
    return [Path(p) for p in written]


#: Cost columns of ``runs.csv`` (:class:`~slamtrials.cost.RunCost`; empty where not measured).
COST_COLUMNS = COST_FIGURES


def _cost_cells(cost: RunCost | None) -> str:
    values = [None if cost is None else getattr(cost, name) for name in COST_COLUMNS]
    return ",".join("" if value is None else f"{value:.6g}" for value in values)


def _mean_cost(runs: tuple[RepeatedRun, ...]) -> dict[str, float | None]:
    """The mean of each cost figure over the runs that have it (``summary.json``'s ``cost``, not reproducible)."""
    means: dict[str, float | None] = {}
    for name in COST_COLUMNS:
        values = [getattr(r.cost, name) for r in runs if r.cost is not None and getattr(r.cost, name) is not None]
        means[f"{name}_mean"] = float(np.mean(values)) if values else None
    return means


def _stats_json(stats: EnvironmentStats, interval: MeanInterval) -> dict[str, float | str]:
    return {
        "mean": stats.mean,
        "std": stats.std_sample,
        "ci_low": interval.low,
        "ci_high": interval.high,
        "ci_method": interval.method,
        "n": stats.n,
    }
