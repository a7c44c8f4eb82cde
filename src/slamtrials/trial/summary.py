"""What a trial reports about itself: :class:`TrialSummary`, stored in run.json under ``trial``.

The trial fills it in; the CLI prints it and a campaign worker copies what its catalog keeps
(:func:`slamtrials.campaign.task.outcome`). ``to_dict`` gives the JSON form (the keys of run.json's
``trial`` object), ``of`` reads it back from a record's metadata.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields
from typing import Any

from slamtrials.record import RunRecord

__all__ = ["TrialSummary", "TRIAL_FORMAT"]

#: Format tag of run.json's ``trial`` object.
TRIAL_FORMAT = "slamtrials-trial/1"


@dataclass(frozen=True)
class TrialSummary:
    """One trial's outcome, coverage and cost.

    Attributes
    ----------
    termination_reason:
        ``map_converged`` (the paper's snapshot rule), ``no_frontiers``, ``time_cap``, ...
    mapped_fraction:
        Share of the free area the robot's footprint can reach that the SLAM map knows, the map aligned
        locally along the path (:func:`~slamtrials.trial.coverage.local_mapped_fraction`).
    mapped_fraction_global:
        The same with the map aligned through the first pose only.
    observed_fraction:
        Share of that area the laser saw (scans traced at the true poses).
    reachable_area_m2:
        The free area the robot's footprint can reach from the start (m^2).
    mapped_fraction_connected, connected_free_area_m2:
        Mapped share of, and area of, all free space connected to the start (m^2).
    mapped_free_area_m2:
        Free area of the final SLAM map (m^2).
    distance_m, turning_rad:
        Distance travelled (m) and total turning of the true heading (rad).
    duration_s, wall_time_s, realtime_factor:
        Simulated duration (s), wall time (s) and their ratio.
    slam_updates, slam_seconds:
        SLAM updates and the wall time spent in the algorithm (s).
    stalled_frames:
        Frames in which the robot bumped into something.
    explorer:
        The explorer's counters (goals, recoveries, blacklisted goals, ...).
    snapshots:
        ``(t, mse)`` of the termination rule's map snapshots (s, grey^2).
    """

    termination_reason: str
    mapped_fraction: float
    mapped_fraction_global: float
    observed_fraction: float
    reachable_area_m2: float
    mapped_fraction_connected: float
    connected_free_area_m2: float
    mapped_free_area_m2: float
    distance_m: float
    turning_rad: float
    duration_s: float
    wall_time_s: float
    realtime_factor: float
    slam_updates: int
    slam_seconds: float
    stalled_frames: int
    explorer: dict[str, float] = field(default_factory=dict)
    snapshots: tuple[tuple[float, float], ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: run.json's ``trial`` object (``format`` first, snapshots as ``[t, mse]`` lists)."""
        doc = {"format": TRIAL_FORMAT, **asdict(self)}
        doc["snapshots"] = [list(pair) for pair in self.snapshots]
        return doc

    @classmethod
    def from_dict(cls, doc: dict[str, Any]) -> TrialSummary:
        """Read the JSON form; a field missing (a run.json of an older version) reads as NaN, 0 or empty."""
        values: dict[str, Any] = {}
        for item in fields(cls):
            value = doc.get(item.name)
            if item.name == "snapshots":
                values[item.name] = tuple((float(t), float(m)) for t, m in (value or ()))
            elif item.name == "explorer":
                values[item.name] = dict(value or {})
            elif item.name == "termination_reason":
                values[item.name] = str(value) if value is not None else "unknown"
            elif item.type in ("int", int):
                values[item.name] = int(value) if value is not None else 0
            else:
                values[item.name] = float(value) if value is not None else math.nan
        return cls(**values)

    @classmethod
    def of(cls, record: RunRecord) -> TrialSummary | None:
        """The summary a trial stored in ``record.metadata["trial"]``, or None for a record of no trial."""
        doc = record.metadata.get("trial")
        return cls.from_dict(doc) if isinstance(doc, dict) else None
