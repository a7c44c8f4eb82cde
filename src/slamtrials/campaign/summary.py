"""The per-world summary of a campaign, like the paper's Table I, read from the catalog.

For each world: its status, the runs done, the mean and standard deviation of the per-run errors
``eps_t`` (m) and ``eps_r`` (rad), their confidence intervals (:func:`slamtrials.metric.environment_stats`
at the run-count rule's confidence and distribution), whether the cap stopped it, and how its runs
ended. :func:`write_summary_csv` saves it as ``summary.csv`` (atomically).

CSV columns: ``world, status, runs, runs_needed, capped, capped_at, eps_t_mean, eps_t_std, eps_t_std_population,
eps_t_ci_low, eps_t_ci_high, eps_r_mean, eps_r_std, eps_r_std_population, eps_r_ci_low, eps_r_ci_high,
confidence, failed_runs, terminations, eps_t_metric_share, eps_r_metric_share`` (``std`` has divisor
``n - 1``, ``std_population`` divisor ``n`` as printed in the paper; ``runs_needed`` the runs the rule
asked for at its last decision, also where the cap stopped the world (``capped`` 1, ``capped_at`` the
cap; empty otherwise); empty cells where a value is undefined; ``terminations`` as ``reason:count;...``; ``*_metric_share``: the metric's share of the
between-run variance, :func:`slamtrials.metric.metric_noise_share`, empty for runs stored without
standard errors), then the mean cost per run, over the runs that recorded one (:mod:`slamtrials.campaign.costsummary`:
``slam_cpu_s_mean, slam_peak_mib_mean, run_cpu_s_mean, run_peak_mib_mean, update_ms_median_mean,
update_ms_p90_mean``: CPU s, MiB, ms per SLAM update; empty for runs of earlier versions; not reproducible),
then the mean map quality per run, over the runs that recorded one (:mod:`slamtrials.campaign.mapsummary`:
``occupied_precision_1_mean, occupied_recall_1_mean, occupied_precision_2_mean, occupied_recall_2_mean,
free_iou_mean, ghost_free_m2_mean``: shares 0..1, m^2; empty for runs without a map and runs of earlier versions).
Then how fast the runs explored (:mod:`slamtrials.campaign.explorationsummary`): ``exploration_runs`` (the
done runs that recorded it), ``coverage_final_mean`` (their mean final coverage, 0..1), ``reached_90``,
``reached_99`` (how many reached 90 % and 99 % coverage), ``time_to_90_s_mean``, ``distance_to_90_m_mean``,
``time_to_99_s_mean``, ``distance_to_99_m_mean`` (mean simulated s and true path m to it, over the runs
that reached it); empty for runs of earlier versions.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from slamtrials.atomicfile import atomic_write_text
from slamtrials.campaign.costsummary import COST_CSV_COLUMNS, WorldCost, cost_csv_cells, world_cost
from slamtrials.campaign.explorationsummary import (
    EXPLORATION_CSV_COLUMNS,
    WorldExploration,
    exploration_csv_cells,
    world_exploration,
)
from slamtrials.campaign.mapsummary import (
    MAP_QUALITY_CSV_COLUMNS,
    WorldMapQuality,
    map_quality_csv_cells,
    world_map_quality,
)
from slamtrials.campaign.store import CampaignStore, RunRow
from slamtrials.metric.noiseshare import metric_noise_share
from slamtrials.metric.stats import EnvironmentStats, environment_stats

__all__ = ["WorldSummary", "summarize_store", "load_summary", "write_summary_csv", "SUMMARY_FILE", "CSV_COLUMNS"]

SUMMARY_FILE = "summary.csv"
CSV_COLUMNS = (
    "world",
    "status",
    "runs",
    "runs_needed",
    "capped",
    "capped_at",
    "eps_t_mean",
    "eps_t_std",
    "eps_t_std_population",
    "eps_t_ci_low",
    "eps_t_ci_high",
    "eps_r_mean",
    "eps_r_std",
    "eps_r_std_population",
    "eps_r_ci_low",
    "eps_r_ci_high",
    "confidence",
    "failed_runs",
    "terminations",
    "eps_t_metric_share",
    "eps_r_metric_share",
    *COST_CSV_COLUMNS,
    *MAP_QUALITY_CSV_COLUMNS,
    *EXPLORATION_CSV_COLUMNS,
)


@dataclass(frozen=True)
class WorldSummary:
    """One row of the summary.

    Attributes
    ----------
    world, status:
        Campaign name and status (pending, running, done, capped, failed, short).
    runs:
        Done runs.
    runs_needed:
        Runs the rule asked for at its last decision, before any cap (None before the first).
    capped:
        The cap stopped the world before the margins were reached.
    cap:
        The cap on runs per world (``runs.max_runs``) where it stopped the world, else None.
    eps_t, eps_r:
        Statistics of the per-run errors (m, rad); None without runs.
    failed_runs:
        Runs that failed.
    terminations:
        ``{termination reason: runs}``.
    note:
        The world's note (why it failed, why a replay is short).
    metric_share_t, metric_share_r:
        The metric's share of the between-run variance of ``eps_t`` and ``eps_r``
        (:func:`~slamtrials.metric.metric_noise_share`); None when a run has no standard error (stored by
        an earlier version) or fewer than 2 runs are done.
    cost:
        The mean cost per done run (:class:`~slamtrials.campaign.costsummary.WorldCost`); None when no run
        recorded one. Left out of equality (not reproducible).
    exploration:
        How fast the done runs explored (:class:`~slamtrials.campaign.explorationsummary.WorldExploration`);
        None when no run recorded it.
    map_quality:
        The mean map quality per done run (:class:`~slamtrials.campaign.mapsummary.WorldMapQuality`); None
        when no run recorded one.
    """

    world: str
    status: str
    runs: int
    runs_needed: int | None
    capped: bool
    eps_t: EnvironmentStats | None
    eps_r: EnvironmentStats | None
    failed_runs: int
    terminations: dict[str, int]
    note: str | None = None
    metric_share_t: float | None = None
    metric_share_r: float | None = None
    cap: int | None = None
    # what the runs cost differs from machine to machine and run to run: not part of the results, so two
    # summaries of the same runs are equal whatever their costs
    cost: WorldCost | None = field(default=None, compare=False)
    map_quality: WorldMapQuality | None = None
    exploration: WorldExploration | None = None


def summarize_store(store: CampaignStore) -> list[WorldSummary]:
    """The summary rows of every world of ``store``, in campaign order."""
    settings = store.config().runs
    rows = []
    runs = store.runs()
    for world in store.worlds():
        mine = [r for r in runs if r.world == world.name]
        done = [r for r in mine if r.status == "done"]
        stats_t = stats_r = None
        if done:
            stats_t = environment_stats(
                [float(r.eps_t) for r in done if r.eps_t is not None],
                confidence=settings.confidence,
                distribution=settings.distribution,
            )
            stats_r = environment_stats(
                [float(r.eps_r) for r in done if r.eps_r is not None],
                confidence=settings.confidence,
                distribution=settings.distribution,
            )
        reasons = Counter(r.termination or "unknown" for r in done)
        share_t, share_r = _metric_shares(done)
        rows.append(
            WorldSummary(
                world.name,
                world.status,
                len(done),
                world.runs_needed,
                bool(world.capped),
                stats_t,
                stats_r,
                sum(r.status == "failed" for r in mine),
                dict(sorted(reasons.items())),
                world.note,
                share_t,
                share_r,
                settings.max_runs if world.capped else None,
                world_cost(json.loads(r.details) for r in done if r.details),
                map_quality=world_map_quality(json.loads(r.details) for r in done if r.details),
                exploration=world_exploration(json.loads(r.details) for r in done if r.details),
            )
        )
    return rows


def _metric_shares(done: list[RunRow]) -> tuple[float | None, float | None]:
    """The metric's share of the between-run variance of eps_t and eps_r, from the runs' standard errors."""
    details = [json.loads(r.details) if r.details else {} for r in done]
    shares: list[float | None] = []
    for metric in ("t", "r"):
        se = [d.get(f"se_{metric}") for d in details]
        if len(done) < 2 or any(value is None for value in se):
            shares.append(None)
            continue
        share = metric_noise_share([float(getattr(r, f"eps_{metric}")) for r in done], se)
        shares.append(None if math.isnan(share) else share)
    return shares[0], shares[1]


def load_summary(folder: str | Path) -> list[WorldSummary]:
    """The summary of the campaign in ``folder`` (read from its catalog)."""
    with CampaignStore.open(folder) as store:
        return summarize_store(store)


def _number(value: float | None) -> str:
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else repr(float(value))


def _stats_cells(stats: EnvironmentStats | None) -> list[str]:
    if stats is None:
        return [""] * 5
    return [
        _number(stats.mean),
        _number(stats.std_sample),
        _number(stats.std_population),
        _number(stats.ci_low),
        _number(stats.ci_high),
    ]


def write_summary_csv(folder: str | Path, rows: list[WorldSummary], confidence: float) -> Path:
    """Write ``<folder>/summary.csv`` atomically and return its path."""
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for row in rows:
        terminations = ";".join(f"{k}:{v}" for k, v in row.terminations.items())
        writer.writerow(
            [
                row.world,
                row.status,
                row.runs,
                "" if row.runs_needed is None else row.runs_needed,
                int(row.capped),
                "" if row.cap is None else row.cap,
                *_stats_cells(row.eps_t),
                *_stats_cells(row.eps_r),
                repr(confidence),
                row.failed_runs,
                terminations,
                _number(row.metric_share_t),
                _number(row.metric_share_r),
                *cost_csv_cells(row.cost),
                *map_quality_csv_cells(row.map_quality),
                *exploration_csv_cells(row.exploration),
            ]
        )
    return atomic_write_text(Path(folder) / SUMMARY_FILE, text.getvalue())
