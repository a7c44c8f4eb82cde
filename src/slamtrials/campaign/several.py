"""``run_campaigns``: several campaigns (a study's cells) run together on one Dask client.

Each campaign is a normal campaign folder, checked, opened, locked and resumed as
:func:`slamtrials.campaign.run_campaign` does it; what differs is that their runs go to one client
through one driver loop (:func:`slamtrials.campaign.driver.drive_lanes`), so the workers take the
runs of every campaign in one priority order (longest first) instead of finishing one campaign before
starting the next. Campaigns that are already complete are not driven (and no cluster is started if
all are).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from slamtrials.campaign.cluster import check_workers, dask_client
from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.driver import Lane, drive_lanes
from slamtrials.campaign.events import CampaignEvent, CampaignResult
from slamtrials.campaign.execute import CampaignPlanner, result_notes
from slamtrials.campaign.folder import (
    campaign_lock,
    check_campaign_folder,
    completed_result,
    open_campaign,
    prepare_resume,
)
from slamtrials.campaign.store import CampaignStore, WorldInfo
from slamtrials.campaign.summary import summarize_store, write_summary_csv
from slamtrials.campaign.task import TrialFn

__all__ = ["CampaignEntry", "run_campaigns", "Priority"]

#: ``(campaign label, its store, world) -> Dask priority`` of the world's runs (higher starts first).
Priority = Callable[[str, CampaignStore, WorldInfo], int]


@dataclass(frozen=True)
class CampaignEntry:
    """One campaign of :func:`run_campaigns`.

    Attributes
    ----------
    label:
        Its name among the others (a study's cell name); unique, part of its Dask task keys.
    config:
        Its validated config.
    folder:
        Its campaign folder (absolute).
    worlds:
        Its resolved worlds (:func:`slamtrials.campaign.worldset.resolve_worlds`).
    """

    label: str
    config: CampaignConfig
    folder: Path
    worlds: tuple[WorldInfo, ...]


def run_campaigns(
    entries: Sequence[CampaignEntry],
    *,
    scheduler: Any = None,
    workers: int | None = None,
    trial_fn: TrialFn | None = None,
    on_event: Callable[[str, CampaignEvent], None] | None = None,
    priority: Priority | None = None,
) -> list[CampaignResult]:
    """Run (or resume) every campaign of ``entries`` on one Dask client; return their results in order.

    Parameters
    ----------
    entries:
        The campaigns (labels unique).
    scheduler, workers, trial_fn:
        As for :func:`slamtrials.campaign.run_campaign`.
    on_event:
        Called with ``(label, event)`` for progress.
    priority:
        Dask priority of a world's runs in one campaign; default: the world's reachable area (m^2).

    Raises
    ------
    ConfigError
        A folder that holds another campaign (checked for every entry before anything is started or
        written).
    """
    started = time.perf_counter()
    if scheduler is None:
        check_workers(workers)
    labels = [e.label for e in entries]
    if len(set(labels)) != len(labels):
        raise ValueError(f"campaign labels must be unique, got {labels}")
    for entry in entries:
        check_campaign_folder(entry.folder, entry.config, entry.worlds, kind="campaign")
    results: dict[str, CampaignResult] = {}
    for entry in entries:
        complete = completed_result(entry.folder, ("done", "capped"))
        if complete is not None:
            results[entry.label] = replace(complete, notes=result_notes(list(complete.summary)))
    pending = [e for e in entries if e.label not in results]
    if pending:
        retries = max(e.config.runs.retries for e in pending)
        with dask_client(scheduler, workers, allowed_failures=retries) as client, ExitStack() as stack:
            lanes = []
            for entry in pending:
                store = stack.enter_context(open_campaign(entry.folder, entry.config, entry.worlds, kind="campaign"))
                stack.enter_context(campaign_lock(entry.folder))
                prepare_resume(store)
                lanes.append(_lane(entry, store, trial_fn, on_event, priority))
            counts = drive_lanes(client, lanes)
            for entry, lane, count in zip(pending, lanes, counts, strict=True):
                summary = summarize_store(lane.store)
                csv_path = write_summary_csv(entry.folder, summary, entry.config.runs.confidence)
                results[entry.label] = CampaignResult(
                    entry.folder,
                    tuple(summary),
                    csv_path,
                    count.done,
                    count.failed,
                    time.perf_counter() - started,
                    result_notes(summary),
                )
    return [results[label] for label in labels]


def _lane(
    entry: CampaignEntry,
    store: CampaignStore,
    trial_fn: TrialFn | None,
    on_event: Callable[[str, CampaignEvent], None] | None,
    priority: Priority | None,
) -> Lane:
    """The driver's lane of one campaign: its planner, its events labelled, its priority."""
    label = entry.label

    def events(event: CampaignEvent) -> None:
        if on_event is not None:
            on_event(label, event)

    def ranks(world: WorldInfo) -> int:
        assert priority is not None
        return priority(label, store, world)

    return Lane(
        store,
        entry.worlds,
        CampaignPlanner(entry.config, entry.folder, trial_fn),
        entry.config.runs.retries,
        events,
        prefix=label,
        priority=ranks if priority is not None else None,
    )
