"""``run_study``: every cell of a study as a campaign, all on one Dask client, longest runs first.

1. Check everything before any work: the study config, every cell's campaign config (a value out of
   range names the cell), every world (loaded once), the study folder (new, or this study: a changed
   config is refused naming the changed keys) and every cell's campaign folder.
2. Write the manifest (``study.json``), then run the cells together
   (:func:`slamtrials.campaign.several.run_campaigns`): one driver loop, one client, the runs of every
   cell in one Dask priority order.
3. Return each cell's :class:`~slamtrials.campaign.CampaignResult`.

Longest first (the LPT rule, which keeps the workers busy to the end): a world's runs in a cell get as
priority the mean wall time (ms) of that cell's runs of that world done so far; before any is done, an
estimate from the world's reachable area (:data:`MS_PER_M2` ms per m^2, about what a demo world's run
takes with online GMapping). The first batch of every cell is thus ordered by world size, and later
batches by what the cell's runs were measured to take (e.g. more particles, longer runs).

Calling it again continues where it stopped; a finished study is the same as an uninterrupted one.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from slamtrials.campaign.cluster import check_workers
from slamtrials.campaign.events import CampaignEvent, CampaignResult
from slamtrials.campaign.folder import check_campaign_folder
from slamtrials.campaign.several import CampaignEntry, run_campaigns
from slamtrials.campaign.store import CampaignStore, WorldInfo
from slamtrials.campaign.task import TrialFn
from slamtrials.campaign.worldset import resolve_worlds
from slamtrials.errors import ConfigError
from slamtrials.study.cells import CELLS_DIR, Cell, expand_cells
from slamtrials.study.config import StudyConfig
from slamtrials.study.folder import check_study_folder, is_study, read_manifest, write_manifest

__all__ = ["run_study", "StudyResult", "PreparedStudy", "prepare_study", "run_priority", "MS_PER_M2"]

#: Estimated wall time of a run per m^2 of reachable area (ms), before any run of the world is measured.
MS_PER_M2 = 200.0


@dataclass(frozen=True)
class PreparedStudy:
    """A study checked and ready to run: its config, cells, folder and each cell's campaign entry."""

    config: StudyConfig
    cells: tuple[Cell, ...]
    folder: Path
    entries: tuple[CampaignEntry, ...]
    resumed: bool


@dataclass(frozen=True)
class StudyResult:
    """The outcome of :func:`run_study`.

    Attributes
    ----------
    folder:
        The study folder.
    cells:
        The cells, in order.
    results:
        Each cell's campaign result, in cell order.
    wall_time:
        Seconds this call took.
    """

    folder: Path
    cells: tuple[Cell, ...]
    results: tuple[CampaignResult, ...]
    wall_time: float

    @property
    def complete(self) -> bool:
        """Whether every cell was already complete when this call started (nothing was run)."""
        return all(r.complete for r in self.results)

    @property
    def runs_done(self) -> int:
        """Runs finished during this call, over all cells."""
        return sum(r.runs_done for r in self.results)

    @property
    def runs_failed(self) -> int:
        """Runs failed during this call, over all cells."""
        return sum(r.runs_failed for r in self.results)


def prepare_study(config: StudyConfig | dict | None, folder: str | Path | None) -> PreparedStudy:
    """Check the study (see the module docstring, step 1) without writing anything.

    ``config`` None resumes the study in ``folder`` with its stored config.

    Raises
    ------
    ConfigError
        Any bad input, named in one line.
    """
    if config is None:
        if folder is None:
            raise ConfigError("give a study config, or the folder of a study to resume")
        folder = Path(folder).absolute()
        if not is_study(folder):
            raise ConfigError(f"{folder}: not a study folder (study.json missing); give a study config to start one")
        config = read_manifest(folder).config
    elif not isinstance(config, StudyConfig):
        config = StudyConfig.from_dict(config)
    target = folder if folder is not None else config.output
    if target is None:
        raise ConfigError("no study folder: give --out (or 'output' in the study config)")
    folder = Path(target).absolute()
    cells = expand_cells(config)
    resumed = check_study_folder(folder, config)
    base = cells[0].config
    worlds = tuple(resolve_worlds(base.worlds, robot_radius=base.sim.robot.radius))
    entries = []
    for cell in cells:
        cell_worlds = worlds
        if cell.config.sim.robot.radius != base.sim.robot.radius:  # the reachable area depends on the robot
            cell_worlds = tuple(resolve_worlds(cell.config.worlds, robot_radius=cell.config.sim.robot.radius))
        entry = CampaignEntry(cell.name, cell.config, folder / CELLS_DIR / cell.name, cell_worlds)
        check_campaign_folder(entry.folder, entry.config, entry.worlds, kind="campaign")
        entries.append(entry)
    return PreparedStudy(config, tuple(cells), folder, tuple(entries), resumed)


def run_priority(label: str, store: CampaignStore, world: WorldInfo) -> int:
    """Dask priority of ``world``'s runs in cell ``label``: their expected wall time in ms (see the module
    docstring): the mean of the cell's done runs of the world, else the reachable area times :data:`MS_PER_M2`."""
    times = [r.wall_time for r in store.runs(world.name) if r.status == "done" and r.wall_time is not None]
    if times:
        return int(round(1000.0 * math.fsum(times) / len(times)))
    area = world.reachable_area if math.isfinite(world.reachable_area) else 0.0
    return int(round(MS_PER_M2 * area))


def run_study(
    config: StudyConfig | dict | None,
    folder: str | Path | None = None,
    *,
    scheduler: Any = None,
    workers: int | None = None,
    trial_fn: TrialFn | None = None,
    on_event: Callable[[str, CampaignEvent], None] | None = None,
) -> StudyResult:
    """Run (or resume) a study; return every cell's result.

    Parameters
    ----------
    config:
        The study config (or a plain dict); None resumes the study in ``folder``.
    folder:
        The study folder; default ``config.output``.
    scheduler, workers, trial_fn:
        As for :func:`slamtrials.campaign.run_campaign`: one client for every cell.
    on_event:
        Called with ``(cell name, event)`` for progress.

    Raises
    ------
    ConfigError
        Bad input (see :func:`prepare_study`), raised before anything is written.
    """
    started = time.perf_counter()
    if scheduler is None:
        check_workers(workers)
    prepared = prepare_study(config, folder)
    if not prepared.resumed:
        write_manifest(prepared.folder, prepared.config, list(prepared.cells))
    results = run_campaigns(
        prepared.entries,
        scheduler=scheduler,
        workers=workers,
        trial_fn=trial_fn,
        on_event=on_event,
        priority=run_priority,
    )
    return StudyResult(prepared.folder, prepared.cells, tuple(results), time.perf_counter() - started)
