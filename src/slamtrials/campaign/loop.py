"""The paper's Section III-C loop as a pure function of the runs completed so far (no I/O, no state).

Per world: run ``initial`` runs (10 in the paper); from the sample variances of their ``eps_t`` and
``eps_r`` compute the runs needed, ``max(N_t, N_r)`` with ``N = ceil(z^2 s^2 / d^2)``
(:func:`slamtrials.metric.runs_needed`); if that is more than the runs done, run up to that many in total
and estimate again; stop when the estimate is not larger than the runs done, or at the cap.

:func:`next_step` replays those decisions from the completed results alone: it starts at
``n = initial`` and, while every run ``0 .. n-1`` is complete, makes the decision on exactly those ``n``
runs and moves ``n`` to the number needed. It stops at the first batch with a missing run (those are the
runs to do next) or at a decision that says ``enough``. Decisions depend only on complete batches of
runs whose results depend only on their seeds, so a campaign resumed after a crash makes the same
decisions, and ends with the same runs, as one that was never interrupted.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from slamtrials.campaign.config import RunSettings
from slamtrials.metric.runcount import RunCount, runs_needed

__all__ = ["WorldStep", "next_step", "decide"]


@dataclass(frozen=True)
class WorldStep:
    """Where a world stands in the run-count loop.

    Attributes
    ----------
    target:
        Runs of the current batch: the world needs runs ``0 .. target-1``.
    missing:
        Run indices below ``target`` without a result (to be run next); empty when ``finished``.
    finished:
        The last decision said ``enough``: no more runs.
    capped:
        Finished because ``max_runs`` cut the number needed (the margins were not reached).
    decision:
        The last decision made (None before the first batch is complete).
    history:
        Every decision made, in order (one per completed batch).
    """

    target: int
    missing: tuple[int, ...]
    finished: bool
    capped: bool
    decision: RunCount | None
    history: tuple[RunCount, ...]


def decide(eps_t: list[float], eps_r: list[float], settings: RunSettings) -> RunCount:
    """One decision of the rule on the per-run errors ``[n]`` (m and rad) of runs ``0 .. n-1``."""
    return runs_needed(
        eps_t,
        eps_r,
        margin_t=settings.margin_t,
        margin_r=settings.margin_r,
        confidence=settings.confidence,
        distribution=settings.distribution,
        min_runs=settings.initial,
        max_runs=settings.max_runs,
    )


def next_step(results: Mapping[int, tuple[float, float]], settings: RunSettings) -> WorldStep:
    """Replay the loop's decisions over a world's completed runs.

    Parameters
    ----------
    results:
        ``{run index: (eps_t, eps_r)}`` of the completed runs (m, rad); other indices may be absent.
    settings:
        The run-count rule.

    Returns
    -------
    WorldStep
    """
    n = settings.initial
    history: list[RunCount] = []
    while True:
        missing = tuple(i for i in range(n) if i not in results)
        if missing:
            return WorldStep(n, missing, False, False, history[-1] if history else None, tuple(history))
        decision = decide([results[i][0] for i in range(n)], [results[i][1] for i in range(n)], settings)
        history.append(decision)
        if decision.enough:
            return WorldStep(n, (), True, decision.capped, decision, tuple(history))
        n = decision.needed
