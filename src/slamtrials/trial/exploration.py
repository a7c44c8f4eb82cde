"""How fast a trial explored, as Explore-Bench reports it: :class:`ExplorationMeasures`, run.json's
``exploration`` object.

*Coverage* at time ``t`` is the share of the world's reachable free area (the cells the robot's footprint
can reach from the start, as ``trial.mapped_fraction`` counts them) that the final SLAM map knows (free or
occupied) and that the SLAM map published at or before ``t`` already knew
(:mod:`slamtrials.trial.firstknown`); so the curve never decreases and ends at ``mapped_fraction``. From
the curve, sampled at the SLAM map's publications (:func:`~slamtrials.trial.firstknown.sample_period`):

* ``time_to_90_s``, ``time_to_99_s``: simulated seconds from the start to the first sample whose
  coverage is at least 0.90 (0.99); None when the run never got there;
* ``distance_to_90_m``, ``distance_to_99_m``: the length of the true path (m) up to that sample;
* ``final_coverage``: the coverage at the end (``trial.mapped_fraction``);
* ``termination_reason``: why the trial ended (``map_converged``, ``no_frontiers``, ``time_cap``, ...);
* ``curve_t``, ``curve_coverage``: the curve, decimated to at most :data:`MAX_CURVE_POINTS` samples
  (the first, the last and the two threshold crossings always kept).

:func:`exploration_measures` computes them from the full curve; ``to_dict`` gives the JSON form, ``of``
reads it back from a record's metadata (None for a run.json of an earlier version, which has none).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "ExplorationMeasures",
    "exploration_measures",
    "decimate",
    "first_reaching",
    "EXPLORATION_FIGURES",
    "EXPLORATION_KEY",
    "EXPLORATION_FORMAT",
    "THRESHOLDS",
    "MAX_CURVE_POINTS",
]

#: run.json key (and metadata key of a record) of a run's exploration measures.
EXPLORATION_KEY = "exploration"
#: Format tag of the ``exploration`` object.
EXPLORATION_FORMAT = "slamtrials-exploration/1"
#: The coverage thresholds of the time and distance measures (Explore-Bench's 90 % and 99 %).
THRESHOLDS = (0.90, 0.99)
#: The single figures of :class:`ExplorationMeasures`, as its attributes and the catalog's ``details`` keys are named.
EXPLORATION_FIGURES = ("final_coverage", "time_to_90_s", "distance_to_90_m", "time_to_99_s", "distance_to_99_m")
#: Most samples of the stored coverage curve.
MAX_CURVE_POINTS = 200


@dataclass(frozen=True)
class ExplorationMeasures:
    """How fast one trial explored (see the module docstring for the definitions).

    Attributes
    ----------
    time_to_90_s, distance_to_90_m:
        Simulated time (s) and true path length (m) from the start until the coverage first reached
        0.90, to the millisecond and millimetre; None when it never did.
    time_to_99_s, distance_to_99_m:
        The same for 0.99.
    final_coverage:
        Coverage at the end of the run (0..1).
    termination_reason:
        Why the trial ended.
    curve_t:
        float64 ``[N]``, N <= :data:`MAX_CURVE_POINTS`: the curve's sample times, simulated seconds
        since the start, increasing.
    curve_coverage:
        float64 ``[N]``: the coverage at those times (0..1), non-decreasing.
    """

    time_to_90_s: float | None
    distance_to_90_m: float | None
    time_to_99_s: float | None
    distance_to_99_m: float | None
    final_coverage: float
    termination_reason: str
    curve_t: tuple[float, ...] = ()
    curve_coverage: tuple[float, ...] = ()

    def reached(self, threshold: float) -> bool:
        """Whether the coverage reached ``threshold`` (0.90 or 0.99)."""
        return self.time_to(threshold) is not None

    def time_to(self, threshold: float) -> float | None:
        """``time_to_90_s`` or ``time_to_99_s``."""
        return self.time_to_90_s if threshold == THRESHOLDS[0] else self.time_to_99_s

    def distance_to(self, threshold: float) -> float | None:
        """``distance_to_90_m`` or ``distance_to_99_m``."""
        return self.distance_to_90_m if threshold == THRESHOLDS[0] else self.distance_to_99_m

    def figures(self) -> dict[str, float | None]:
        """The :data:`EXPLORATION_FIGURES` by name (what a campaign's catalog keeps of a run)."""
        return {name: getattr(self, name) for name in EXPLORATION_FIGURES}

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: run.json's ``exploration`` object (``format`` first, the curve as two lists)."""
        return {
            "format": EXPLORATION_FORMAT,
            "time_to_90_s": self.time_to_90_s,
            "distance_to_90_m": self.distance_to_90_m,
            "time_to_99_s": self.time_to_99_s,
            "distance_to_99_m": self.distance_to_99_m,
            "final_coverage": self.final_coverage,
            "termination_reason": self.termination_reason,
            "curve": {"t": list(self.curve_t), "coverage": list(self.curve_coverage)},
        }

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> ExplorationMeasures:
        """Read the JSON form (a missing figure reads as None, NaN or empty)."""
        curve = doc.get("curve") or {}
        final = _number(doc.get("final_coverage"))
        return cls(
            time_to_90_s=_number(doc.get("time_to_90_s")),
            distance_to_90_m=_number(doc.get("distance_to_90_m")),
            time_to_99_s=_number(doc.get("time_to_99_s")),
            distance_to_99_m=_number(doc.get("distance_to_99_m")),
            final_coverage=math.nan if final is None else final,
            termination_reason=str(doc.get("termination_reason") or "unknown"),
            curve_t=tuple(float(v) for v in curve.get("t") or ()),
            curve_coverage=tuple(float(v) for v in curve.get("coverage") or ()),
        )

    @classmethod
    def of(cls, metadata: Mapping[str, Any]) -> ExplorationMeasures | None:
        """The measures a trial stored in ``metadata`` (a record's, or a parsed run.json); None when it
        holds none (a run of an earlier version, or a record that no trial made)."""
        doc = metadata.get(EXPLORATION_KEY)
        return cls.from_dict(doc) if isinstance(doc, Mapping) else None


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def first_reaching(coverage: NDArray[np.float64], threshold: float) -> int | None:
    """Index of the first sample of ``coverage`` ``[S]`` that is at least ``threshold``; None if none is."""
    hits = np.flatnonzero(np.asarray(coverage, dtype=np.float64) >= threshold)
    return int(hits[0]) if hits.size else None


def decimate(count: int, keep: tuple[int, ...] = (), max_points: int = MAX_CURVE_POINTS) -> NDArray[np.intp]:
    """Increasing indices into ``count`` samples: all of them when ``count <= max_points``, else at most
    ``max_points`` spread evenly, always with the first, the last and every index in ``keep``."""
    if count <= max_points:
        return np.arange(count, dtype=np.intp)
    must = np.array(sorted({0, count - 1, *(int(k) for k in keep if 0 <= k < count)}), dtype=np.intp)
    if max_points < must.size:
        raise ValueError(f"max_points {max_points} cannot hold the {must.size} samples that must be kept")
    others = np.setdiff1d(np.arange(count, dtype=np.intp), must)
    free = max_points - must.size
    if free == 0:
        return must
    spread = np.floor(np.linspace(0.0, others.size - 1, free) + 0.5).astype(np.intp)  # distinct: step >= 1
    return np.union1d(must, others[spread])


def exploration_measures(
    t: ArrayLike,
    coverage: ArrayLike,
    distance: ArrayLike,
    termination_reason: str,
    *,
    max_points: int = MAX_CURVE_POINTS,
) -> ExplorationMeasures:
    """The measures of one trial from its full coverage curve.

    Parameters
    ----------
    t:
        float64 ``[S]`` sample times, simulated seconds since the start, increasing.
    coverage:
        float64 ``[S]`` coverage at those times (0..1).
    distance:
        float64 ``[S]`` length of the true path (m) from the start to each sample.
    termination_reason:
        Why the trial ended.
    max_points:
        Most samples of the stored curve (:func:`decimate`).
    """
    t = np.asarray(t, dtype=np.float64)
    coverage = np.asarray(coverage, dtype=np.float64)
    distance = np.asarray(distance, dtype=np.float64)
    if not (t.shape == coverage.shape == distance.shape) or t.ndim != 1:
        raise ValueError(
            f"t, coverage and distance must be [S] alike, got {t.shape}, {coverage.shape}, {distance.shape}"
        )
    crossings = [first_reaching(coverage, threshold) for threshold in THRESHOLDS]
    times = [None if k is None else round(float(t[k]), 3) for k in crossings]  # as the curve's times
    lengths = [None if k is None else round(float(distance[k]), 3) for k in crossings]
    kept = decimate(t.shape[0], tuple(k for k in crossings if k is not None), max_points)
    return ExplorationMeasures(
        time_to_90_s=times[0],
        distance_to_90_m=lengths[0],
        time_to_99_s=times[1],
        distance_to_99_m=lengths[1],
        final_coverage=float(coverage[-1]) if coverage.size else 0.0,
        termination_reason=str(termination_reason),
        curve_t=tuple(round(float(v), 3) for v in t[kept]),
        curve_coverage=tuple(round(float(v), 5) for v in coverage[kept]),
    )
