"""A run's two numbers, ``eps_t`` and ``eps_r``: its SLAM estimate's mean errors over its relation set.

Every run has one relation set (:class:`~slamtrials.metric.RelationSet`), drawn once from its ground
truth with ``numpy.random.default_rng(seed)`` by the campaign's sampling rule, sized on the run's SLAM
estimate, and stored in the run folder (``relations.npz``). The SLAM estimate, the online estimate and
the odometry are all scored on that set; a replay scores its new estimate on the source run's set, so a
campaign and its replay are compared on the same relations. Estimates are matched to the truth's
timestamps within ``metric.tolerance`` and the odometry carries any frame without an estimate.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from slamtrials.campaign.config import MetricSettings
from slamtrials.errors import MetricError
from slamtrials.metric import RelationSet, SetScore, draw_relation_set, score_on_set
from slamtrials.record import RunRecord, Trajectory

__all__ = ["RunScore", "score_run", "run_relation_set"]


@dataclass(frozen=True, eq=False)
class RunScore:
    """The evaluation of one run on its relation set.

    Attributes
    ----------
    relation_set:
        The run's relation set.
    estimate:
        The SLAM estimate's score (``eps_t`` m, ``eps_r`` rad and their standard errors).
    online:
        The online estimate's score, when the record has one.
    odometry:
        The odometry's score (the same relations, no SLAM).
    scored:
        Which SLAM estimate the run's ``eps_t``, ``eps_r`` are: ``final`` or ``online`` (``metric.estimate``).
    """

    relation_set: RelationSet
    estimate: SetScore
    online: SetScore | None
    odometry: SetScore
    scored: str = "final"

    @property
    def run(self) -> SetScore:
        """The score that is the run's (the final or the online estimate's)."""
        if self.scored == "online":
            assert self.online is not None
            return self.online
        return self.estimate

    @property
    def eps_t(self) -> float:
        """The run's mean translational error (m)."""
        return self.run.eps_t

    @property
    def eps_r(self) -> float:
        """The run's mean rotational error (rad)."""
        return self.run.eps_r

    def to_dict(self) -> dict[str, Any]:
        """What run.json keeps under ``campaign``: errors, standard errors, relation count, the set's draw."""
        rs = self.relation_set

        def entry(score: SetScore) -> dict[str, float]:
            return {"eps_t": score.eps_t, "eps_r": score.eps_r, "se_t": score.se_t, "se_r": score.se_r}

        scores = {"estimate": entry(self.estimate), "odometry": entry(self.odometry)}
        if self.online is not None:
            scores["online"] = entry(self.online)
        return {
            "eps_t": self.eps_t,
            "eps_r": self.eps_r,
            "se_t": self.run.se_t,
            "se_r": self.run.se_r,
            "scored_estimate": self.scored,
            "relations": len(rs),
            "relation_set": {
                "seed": rs.seed,
                "rule": rs.rule.rule,
                "sized_on": rs.sized_on,
                "needed_t": rs.needed_t,
                "needed_r": rs.needed_r,
                "capped": rs.capped,
            },
            "scores": scores,
        }


def _trajectories(record: RunRecord) -> tuple[Trajectory, Trajectory]:
    return Trajectory(t=record.t, poses=record.truth), Trajectory(t=record.t, poses=record.odometry)


def score_run(
    record: RunRecord, seed: int, metric: MetricSettings, relation_set: RelationSet | None = None
) -> RunScore:
    """Score ``record``'s estimates (``[T, 3]``, map frame) against its truth (``[T, 3]``, world frame).

    Parameters
    ----------
    record:
        The run, with a SLAM estimate.
    seed:
        Seed of the relation set's draw when ``relation_set`` is None.
    metric:
        Sampling rule and matching tolerance.
    relation_set:
        The run's stored set (a replay's source run's); None draws one, sized on ``record.estimate``.

    Raises
    ------
    MetricError
        The record has no estimate, or the metric cannot evaluate it.
    """
    if record.estimate is None:
        raise MetricError("the run has no SLAM estimate to evaluate", what="estimate")
    truth, odometry = _trajectories(record)
    estimate = Trajectory(t=record.t, poses=np.asarray(record.estimate, dtype=np.float64))
    if relation_set is None:
        relation_set, _ = draw_relation_set(
            truth, estimate, seed=int(seed), rule=metric.sampling, tolerance=metric.tolerance, odometry=odometry
        )

    def score(trajectory: Trajectory, what: str) -> SetScore:
        return score_on_set(relation_set, truth, trajectory, tolerance=metric.tolerance, odometry=odometry, what=what)

    online = None
    if record.online is not None:
        online = score(Trajectory(t=record.t, poses=np.asarray(record.online, dtype=np.float64)), "online")
    elif metric.estimate == "online":
        raise MetricError(
            "metric.estimate is online but the run has no online estimate (recorded by an earlier version)",
            what="estimate",
        )
    return RunScore(
        relation_set, score(estimate, "estimate"), online, score(odometry, "odometry"), scored=metric.estimate
    )


def run_relation_set(folder: str | Path, record: RunRecord, seed: int, metric: MetricSettings) -> RelationSet:
    """The relation set of the run in ``folder`` (``record`` read from it).

    Its stored ``relations.npz``; for a run folder of an earlier version, which has none, the set drawn
    as that version drew it (the same seed, rule and estimate give the same pairs), so a replay of an old
    campaign is still scored on the relations its source was.

    Raises
    ------
    FormatError
        A stored set that is not readable.
    MetricError
        A stored set of another run, or a record that cannot be scored.
    """
    from slamtrials.campaign.relationsetfile import read_relation_set
    from slamtrials.io.layout import RunFolder

    files = RunFolder(folder)
    if files.relation_set.is_file():
        relation_set = read_relation_set(files.relation_set)
        relation_set.relations(Trajectory(t=record.t, poses=record.truth))  # refuses a set of another run
        return relation_set
    truth, odometry = _trajectories(record)
    sized = record.estimate if record.estimate is not None else record.odometry
    relation_set, _ = draw_relation_set(
        truth,
        Trajectory(t=record.t, poses=np.asarray(sized, dtype=np.float64)),
        seed=int(seed),
        rule=metric.sampling,
        tolerance=metric.tolerance,
        odometry=odometry,
        sized_on="estimate" if record.estimate is not None else "odometry",
    )
    return relation_set
