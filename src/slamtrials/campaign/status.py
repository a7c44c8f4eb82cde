"""``slamtrials campaign status``: how far a campaign has got, read from its catalog (no Dask needed)."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from slamtrials.campaign.config import CampaignConfig
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
        The ``worlds`` rows (status, runs needed so far, last decision).
    runs:
        ``{world: {run status: count}}``.
    summary:
        The per-world summary over the runs done so far.
    created:
        When the campaign was created (ISO, UTC).
    """

    folder: Path
    kind: str
    config: CampaignConfig
    worlds: tuple[WorldRow, ...]
    runs: dict[str, dict[str, int]]
    summary: tuple[WorldSummary, ...]
    created: str | None

    @property
    def finished(self) -> bool:
        """Every world is done, capped or short (nothing left to run)."""
        return all(w.status in ("done", "capped", "short") for w in self.worlds)

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
        runs: dict[str, Counter] = {w.name: Counter() for w in store.worlds()}
        for row in store.runs():
            runs[row.world][row.status] += 1
        return CampaignStatus(
            Path(folder),
            store.kind,
            store.config(),
            tuple(store.worlds()),
            {k: dict(v) for k, v in runs.items()},
            tuple(summarize_store(store)),
            store.meta("created"),
        )
