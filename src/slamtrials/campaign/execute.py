"""``run_campaign``: the whole campaign on Dask, with a durable store and resume.

1. Validate everything before any work: the config (including the SLAM parameters), every world (each
   loaded once), and the folder (a new one, or a campaign of the same config and worlds).
2. Open the catalog (:mod:`slamtrials.campaign.store`), lock the folder, and put back what an
   interrupted driver left (:func:`slamtrials.campaign.folder.prepare_resume`).
3. Connect to Dask (:mod:`slamtrials.campaign.cluster`) and drive every world through the paper's
   Section III-C loop (:mod:`slamtrials.campaign.loop`, :mod:`slamtrials.campaign.driver`); each run is
   a task (:func:`slamtrials.campaign.task.run_one`) with its own seed
   (:func:`slamtrials.campaign.seeds.run_seed`).
4. Write ``summary.csv`` and return the per-world summary.

Calling it again on the same folder continues where it stopped; the finished campaign is the same as
an uninterrupted one with the same config (same runs, seeds and errors).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from slamtrials.campaign.cluster import check_workers, dask_client
from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.driver import Plan, drive
from slamtrials.campaign.events import CampaignEvent, CampaignResult
from slamtrials.campaign.folder import (
    campaign_lock,
    check_campaign_folder,
    completed_result,
    open_campaign,
    prepare_resume,
)
from slamtrials.campaign.loop import next_step
from slamtrials.campaign.results import RunResult
from slamtrials.campaign.seeds import run_seed
from slamtrials.campaign.store import CampaignStore, WorldInfo, is_campaign
from slamtrials.campaign.summary import summarize_store, write_summary_csv
from slamtrials.campaign.task import RunTask, TrialFn, run_one
from slamtrials.campaign.worldset import load_world_cached, resolve_worlds
from slamtrials.errors import ConfigError, SlamtrialsError

__all__ = ["run_campaign", "CampaignPlanner", "result_notes"]


class CampaignPlanner:
    """The planner of a simulated campaign: the Section III-C loop, and a :class:`RunTask` per run."""

    def __init__(self, config: CampaignConfig, folder: Path, trial_fn: TrialFn | None = None):
        self.config = config
        self.folder = folder
        self.trial_fn = trial_fn
        self.trial = config.trial_config()

    def plan(self, world: WorldInfo, results: dict[int, tuple[float, float]]) -> Plan:
        step = next_step(results, self.config.runs)
        if step.finished:
            return Plan(step.target, (), "capped" if step.capped else "done", step.decision)
        return Plan(step.target, step.missing, None, step.decision)

    def task(self, world: WorldInfo, index: int) -> tuple[Callable[[Any], RunResult], RunTask, int]:
        seed = run_seed(self.config.seed, world.name, index)
        task = RunTask(
            str(self.folder),
            world.name,
            world.ref,
            index,
            seed,
            self.trial,
            self.config.metric,
            self.trial_fn,
            extra={"root_seed": self.config.seed},
        )
        return run_one, task, seed


def _stored_worlds(store: CampaignStore) -> list[WorldInfo]:
    """The stored worlds of a campaign, each checked to load (for a resume without the config)."""
    worlds = store.world_infos()
    for world in worlds:
        try:
            load_world_cached(world.ref)
        except (SlamtrialsError, OSError) as exc:
            raise ConfigError(f"worlds: world {world.name!r} ({world.ref}) does not load: {exc}") from None
    return worlds


def result_notes(summary: list) -> tuple[str, ...]:
    """Remarks about capped, failed and short worlds for the output."""
    notes = []
    for row in summary:
        if row.status == "capped":
            notes.append(
                f"{row.world}: stopped at the cap of {row.cap or row.runs} runs; the rule asked for "
                f"{row.runs_needed or 'more'}, the margins are not reached"
            )
        elif row.status == "failed":
            notes.append(f"{row.world}: failed ({row.note or 'see the runs table'}); resume to retry")
        elif row.status == "short":
            notes.append(f"{row.world}: {row.note}")
    return tuple(notes)


def run_campaign(
    config: CampaignConfig | dict | None,
    folder: str | Path | None = None,
    *,
    scheduler: Any = None,
    workers: int | None = None,
    trial_fn: TrialFn | None = None,
    on_event: Callable[[CampaignEvent], None] | None = None,
) -> CampaignResult:
    """Run (or resume) a campaign and return its per-world summary.

    Parameters
    ----------
    config:
        The campaign config (a :class:`CampaignConfig` or a plain dict); None resumes the campaign in
        ``folder`` with its stored config and worlds.
    folder:
        The campaign folder; default ``config.output``.
    scheduler:
        None for a local Dask cluster, a scheduler address, or a ``distributed.Client``.
    workers:
        Worker processes of the local cluster (default: one per core).
    trial_fn:
        ``(world, trial_config, seed) -> RunRecord`` instead of :func:`slamtrials.trial.run_trial`
        (tests; e.g. :class:`slamtrials.campaign.testing.FakeTrial`).
    on_event:
        Called with a :class:`CampaignEvent` for progress.

    Returns
    -------
    CampaignResult
        With ``complete`` set (and nothing run, no cluster started) if every world of the folder's
        campaign was already done or capped.

    Raises
    ------
    ConfigError
        A bad config, a world that does not load, or a folder that holds another campaign; raised
        before any work starts, with nothing in the folder changed.
    """
    started = time.perf_counter()
    if scheduler is None:
        check_workers(workers)
    if config is None:
        if folder is None:
            raise ConfigError("give a campaign config, or the folder of a campaign to resume")
        folder = Path(folder).absolute()
        if not is_campaign(folder):
            raise ConfigError(f"{folder}: not a campaign folder (campaign.sqlite missing); give a config to start one")
        with CampaignStore.open(folder) as probe:
            config = probe.config()
            worlds = _stored_worlds(probe)
    else:
        if not isinstance(config, CampaignConfig):
            config = CampaignConfig.from_dict(config)
        else:
            config = CampaignConfig.from_dict(config.model_dump(mode="json"))  # re-check the SLAM parameters
        target = folder if folder is not None else config.output
        if target is None:
            raise ConfigError("no campaign folder: give --out (or 'output' in the config)")
        folder = Path(target).absolute()
        worlds = resolve_worlds(config.worlds, robot_radius=config.sim.robot.radius)
    if config.replay_of is not None:
        raise ConfigError(
            f"the config is that of a replay of {config.replay_of}; continue it with 'slamtrials campaign replay'"
        )

    check_campaign_folder(folder, config, worlds, kind="campaign")  # before starting a cluster; touches nothing
    complete = completed_result(folder, ("done", "capped"))
    if complete is not None:
        summary = list(complete.summary)
        return replace(complete, notes=result_notes(summary))
    planner = CampaignPlanner(config, folder, trial_fn)
    with dask_client(scheduler, workers, allowed_failures=config.runs.retries) as client:
        store = open_campaign(folder, config, worlds, kind="campaign")
        with store, campaign_lock(folder):
            prepare_resume(store)
            counts = drive(store, client, worlds, planner, retries=config.runs.retries, on_event=on_event)
            summary = summarize_store(store)
            csv_path = write_summary_csv(folder, summary, config.runs.confidence)
    return CampaignResult(
        folder,
        tuple(summary),
        csv_path,
        counts.done,
        counts.failed,
        time.perf_counter() - started,
        result_notes(summary),
    )
