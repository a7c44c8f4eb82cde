"""How many runs an environment needs: the rule of the paper's Section III-C.

Start with ``min_runs`` runs (10 in the paper); estimate the variance of the per-run errors ``eps_t``
and ``eps_r`` over them (unbiased, divisor ``R - 1``); ``N_t = ceil(z^2 s_t^2 / d_t^2)``, ``N_r`` likewise,
and the runs needed in total are ``max(N_t, N_r)``. If that is more than the runs done, do that many in
total and estimate again; stop when the newly estimated number is not larger than the runs performed.
:func:`runs_needed` is one step of that loop; :func:`replay_run_count` runs the loop over a given
sequence of per-run errors (for tests and for re-evaluating stored campaigns).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from slamtrials.errors import MetricError
from slamtrials.metric.quantiles import Distribution, critical_value
from slamtrials.metric.sampling import sample_size

__all__ = ["DEFAULT_MIN_RUNS", "RunCount", "runs_needed", "replay_run_count"]

#: Runs of the initial estimate, as in the paper.
DEFAULT_MIN_RUNS = 10


@dataclass(frozen=True)
class RunCount:
    """One decision of the run-count rule.

    Attributes
    ----------
    done:
        Runs performed so far.
    needed:
        Runs needed in total: ``max(needed_t, needed_r, min_runs)``, capped at ``max_runs``.
    needed_t, needed_r:
        ``ceil(z^2 s^2 / d^2)`` for the translational and rotational errors (0 before ``min_runs`` runs,
        when the variance is not estimated yet).
    std_t, std_r:
        Sample standard deviations (divisor ``done - 1``) of the per-run errors; NaN before ``min_runs`` runs.
    critical:
        The quantile ``z`` used (NaN before ``min_runs`` runs).
    enough:
        ``needed <= done``: stop.
    capped:
        The cap ``max_runs`` cut ``needed`` (report it: the environment did not reach the margins).
    """

    done: int
    needed: int
    needed_t: int
    needed_r: int
    std_t: float
    std_r: float
    critical: float
    enough: bool
    capped: bool

    @property
    def asked(self) -> int:
        """Runs the rule asks for before any cap: ``max(needed_t, needed_r, min_runs)`` (``needed`` unless
        ``capped``)."""
        return max(self.needed, self.needed_t, self.needed_r)


def runs_needed(
    eps_t: ArrayLike,
    eps_r: ArrayLike,
    *,
    margin_t: float,
    margin_r: float,
    confidence: float = 0.99,
    distribution: Distribution = "t",
    sides: int = 2,
    min_runs: int = DEFAULT_MIN_RUNS,
    max_runs: int | None = None,
) -> RunCount:
    """How many runs in total an environment needs, given the per-run errors of the runs done so far.

    Parameters
    ----------
    eps_t, eps_r:
        ``[R]`` per-run translational (m) and rotational (rad) errors (each run's mean over its relations).
    margin_t, margin_r:
        Margins of error ``d_t`` (m) and ``d_r`` (rad) of the environment's mean errors.
    confidence:
        Confidence level (default 0.99).
    distribution, sides:
        Quantile: two-sided Student t with ``R - 1`` degrees of freedom by default; ``"normal"`` is the
        paper's (too small with few runs).
    min_runs:
        Runs before the first variance estimate (10 in the paper; at least 2).
    max_runs:
        Optional cap on the runs per environment.

    Returns
    -------
    RunCount

    Raises
    ------
    MetricError
        Arrays of different lengths, non-finite errors or bad settings.
    """
    t = np.asarray(eps_t, dtype=np.float64).reshape(-1)
    r = np.asarray(eps_r, dtype=np.float64).reshape(-1)
    if len(t) != len(r):
        raise MetricError(f"eps_t has {len(t)} runs but eps_r has {len(r)}")
    bad = ~(np.isfinite(t) & np.isfinite(r))
    if bad.any():
        i = int(np.argmax(bad))
        raise MetricError(f"run {i} has a non-finite error (eps_t={t[i]}, eps_r={r[i]})", what="runs", index=i)
    if min_runs < 2:
        raise MetricError(f"min_runs must be at least 2 (a variance needs two runs), got {min_runs}")
    if max_runs is not None and max_runs < min_runs:
        raise MetricError(f"max_runs ({max_runs}) must be at least min_runs ({min_runs})")
    done = len(t)
    if done < min_runs:
        needed = min_runs
        return RunCount(done, needed, 0, 0, math.nan, math.nan, math.nan, False, False)
    critical = critical_value(confidence, distribution=distribution, dof=done - 1, sides=sides)
    std_t = float(np.std(t, ddof=1))
    std_r = float(np.std(r, ddof=1))
    needed_t = sample_size(std_t, margin_t, critical)
    needed_r = sample_size(std_r, margin_r, critical)
    wanted = max(needed_t, needed_r, min_runs)
    needed = wanted if max_runs is None else min(wanted, max_runs)
    return RunCount(done, needed, needed_t, needed_r, std_t, std_r, critical, needed <= done, needed < wanted)


def replay_run_count(eps_t: ArrayLike, eps_r: ArrayLike, **options) -> RunCount | None:
    """Run the iterative rule over per-run errors given in the order the runs would be performed.

    Starts with the first ``min_runs`` runs, then repeatedly takes as many runs as the last decision asked
    for, until a decision says ``enough``.

    Parameters
    ----------
    eps_t, eps_r:
        ``[R]`` per-run errors, in run order.
    **options:
        Keyword options of :func:`runs_needed` (``margin_t`` and ``margin_r`` are required).

    Returns
    -------
    RunCount or None
        The final decision (``done`` = the runs the rule performed), or None when the rule asks for more
        runs than the sequence holds.
    """
    t = np.asarray(eps_t, dtype=np.float64).reshape(-1)
    r = np.asarray(eps_r, dtype=np.float64).reshape(-1)
    done = options.get("min_runs", DEFAULT_MIN_RUNS)
    while done <= len(t):
        decision = runs_needed(t[:done], r[:done], **options)
        if decision.enough:
            return decision
        done = decision.needed
    return None
