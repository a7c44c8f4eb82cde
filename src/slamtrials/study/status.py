"""``slamtrials study status``: how far every cell of a study has got (read from the cells' catalogs)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from slamtrials.campaign.status import CampaignStatus, campaign_status
from slamtrials.campaign.store import is_campaign
from slamtrials.study.config import StudyConfig
from slamtrials.study.folder import read_manifest

__all__ = ["CellStatus", "StudyStatus", "study_status"]


@dataclass(frozen=True)
class CellStatus:
    """One cell's progress: its name, settings (``{key: value}``), folder, and its campaign's status
    (None before its campaign folder exists)."""

    name: str
    settings: dict[str, Any]
    folder: Path
    campaign: CampaignStatus | None

    @property
    def finished(self) -> bool:
        """Every world of the cell is done, capped or short."""
        return self.campaign is not None and self.campaign.finished


@dataclass(frozen=True)
class StudyStatus:
    """A snapshot of a study: its config, when it was created, and every cell's :class:`CellStatus`."""

    folder: Path
    config: StudyConfig
    created: str
    cells: tuple[CellStatus, ...]

    @property
    def finished(self) -> bool:
        """Every cell is finished."""
        return all(c.finished for c in self.cells)

    @property
    def runs_done(self) -> int:
        """Done runs over every cell."""
        return sum(c.campaign.runs_done for c in self.cells if c.campaign is not None)


def study_status(folder: str | Path) -> StudyStatus:
    """Read the progress of the study in ``folder``.

    Raises
    ------
    ConfigError
        ``folder`` holds no study.
    """
    folder = Path(folder)
    manifest = read_manifest(folder)
    cells = []
    for entry in manifest.cells:
        cell_folder = folder / entry["folder"]
        status = campaign_status(cell_folder) if is_campaign(cell_folder) else None
        cells.append(CellStatus(entry["name"], dict(entry["settings"]), cell_folder, status))
    return StudyStatus(folder, manifest.config, manifest.created, tuple(cells))
