"""What a running campaign reports (:class:`CampaignEvent`) and returns (:class:`CampaignResult`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

__all__ = ["CampaignEvent", "CampaignResult", "EventKind", "REPLAY_NOTE"]

EventKind = Literal["start", "batch", "run_done", "run_failed", "world_done"]

#: What a replay's output says about the paths of its runs.
REPLAY_NOTE = (
    "replay: the robot's paths are those explored with the first algorithm's maps "
    "(recorded by the source campaign); only the SLAM algorithm was run again"
)


@dataclass(frozen=True)
class CampaignEvent:
    """A progress report of :func:`slamtrials.campaign.run_campaign` (passed to ``on_event``).

    Attributes
    ----------
    kind:
        ``start`` (once per world, before any run), ``batch`` (runs submitted), ``run_done``,
        ``run_failed``, ``world_done`` (the world needs no more runs, or failed, or is short of runs).
    world:
        The world's campaign name.
    target:
        Runs the world needs so far (grows as the rule asks for more).
    done:
        Runs of the world done so far.
    index:
        The run's index (run events), or None.
    eps_t, eps_r:
        The run's errors (m, rad), for ``run_done``.
    status:
        The world's status for ``start`` and ``world_done`` (pending, running, done, capped, failed, short).
    message:
        A failed run's error, or a note.
    """

    kind: EventKind
    world: str
    target: int
    done: int
    index: int | None = None
    eps_t: float | None = None
    eps_r: float | None = None
    status: str | None = None
    message: str = ""


@dataclass(frozen=True)
class CampaignResult:
    """The outcome of :func:`~slamtrials.campaign.run_campaign` or :func:`~slamtrials.campaign.replay_campaign`.

    Attributes
    ----------
    folder:
        The campaign folder.
    summary:
        One :class:`~slamtrials.campaign.summary.WorldSummary` per world (the paper's Table I).
    summary_csv:
        The CSV file of the summary.
    runs_done, runs_failed:
        Runs finished and failed during this call (a resumed campaign counts only the new ones).
    wall_time:
        Seconds this call took.
    notes:
        Things the reader must know (capped worlds, failed worlds, replay's paths).
    complete:
        The campaign was already complete when this call started (nothing was run, no cluster started).
    """

    folder: Path
    summary: tuple
    summary_csv: Path
    runs_done: int
    runs_failed: int
    wall_time: float
    notes: tuple[str, ...] = field(default_factory=tuple)
    complete: bool = False
