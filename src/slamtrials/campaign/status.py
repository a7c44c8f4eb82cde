"""``slamtrials campaign status``: how far a campaign has got, read from its catalog (no Dask needed).

A run (or world) that the catalog says is ``running`` while no driver holds the campaign's lock
(:func:`~slamtrials.campaign.folder.driver_alive`) was running when its driver was interrupted: it is
shown as ``interrupted`` (the next ``campaign run --out`` or ``campaign replay`` runs it again).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace
from pathlib import Path

from slamtrials.campaign.config import CampaignConfig
from slamtrials.campaign.folder import driver_alive
from slamtrials.campaign.store import CampaignStore, WorldRow
from slamtrials.campaign.summary import WorldSummary, summarize_store

__all__ = ["CampaignStatus", "campaign_status"]


@dataclass(frozen=True)
class CampaignStatus:
    """A snapshot of a campaign's progress.

    Attributes
    ----------
    folder:
        The campaign folder.
    kind:
        ``campaign`` or ``replay``.
    config:
        The stored config.
    worlds:
        The ``worlds`` rows (status, runs needed so far, last decision); ``interrupted`` for a world
        ``running`` when no driver is alive.
    runs:
        ``{world: {run status: count}}``; ``interrupted`` counts the runs the catalog says are
        ``running`` when no driver is alive.
    summary:
        The per-world summary over the runs done so far (a world's status as in ``worlds``).
    created:
        When the campaign was created (ISO, UTC).
    driver:
        Whether a driver is running the campaign now (None: cannot tell on this system).
    """

    folder: Path
    kind: str
    config: CampaignConfig
    worlds: tuple[WorldRow, ...]
    runs: dict[str, dict[str, int]]
    summary: tuple[WorldSummary, ...]
    created: str | None
    driver: bool | None = None

    @property
    def finished(self) -> bool:
        """Every world is done, capped or short (nothing left to run)."""
        return all(w.status in ("done", "capped", "short") for w in self.worlds)

    @property
    def interrupted(self) -> bool:
        """No driver is alive but some runs were left running."""
        return any(counts.get("interrupted", 0) for counts in self.runs.values())

    @property
    def runs_done(self) -> int:
        """Done runs over all worlds."""
        return sum(counts.get("done", 0) for counts in self.runs.values())


def campaign_status(folder: str | Path) -> CampaignStatus:
    """Read the progress of the campaign in ``folder``.

    Raises
    ------
    ConfigError
        ``folder`` holds no campaign.
    """
    with CampaignStore.open(folder) as store:
        driver = driver_alive(Path(folder))
        lost = driver is False  # rows left 'running' by a driver that is gone
        worlds = [replace(w, status="interrupted") if lost and w.status == "running" else w for w in store.worlds()]
        runs: dict[str, Counter] = {w.name: Counter() for w in worlds}
        for row in store.runs():
            runs[row.world]["interrupted" if lost and row.status == "running" else row.status] += 1
        return CampaignStatus(
            Path(folder),
            store.kind,
            store.config(),
            tuple(worlds),
            {k: dict(v) for k, v in runs.items()},
            tuple(
                replace(row, status="interrupted") if lost and row.status == "running" else row
                for row in summarize_store(store)
            ),
            store.meta("created"),
            driver,
        )
