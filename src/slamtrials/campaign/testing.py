"""A cheap stand-in for a trial, for tests and benchmarks of the campaign machinery.

:class:`FakeTrial` returns, in microseconds, a two-frame :class:`~slamtrials.record.RunRecord` whose
evaluation gives exactly the errors it drew: the truth moves 1 m along x; the estimate moves
``1 + e_t`` m and turns ``e_r`` rad, so every sampled relation (there is only one pair of poses) has
translational error ``e_t`` and rotational error ``e_r``. ``e_t`` and ``e_r`` are drawn from normal
distributions (clipped at 0) with ``numpy.random.default_rng(seed)``, so their variance across runs is
known and the expected run counts of the Section III-C rule can be computed independently.

With ``map_offset`` the estimate (and the map) is expressed in a map frame other than the world frame:
``estimate = map_offset (+) estimate_in_world``, a rigid motion that leaves every relative error, and so
``e_t`` and ``e_r``, unchanged (the default, no offset, gives the same numbers bit for bit).

Pass it as ``trial_fn`` to :func:`slamtrials.campaign.run_campaign`. It is a module-level class so that
Dask workers can unpickle it by reference.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from slamtrials.cost import COST_KEY, RunCost
from slamtrials.geometry import compose
from slamtrials.record import LaserGeometry, OccupancyGrid, RunRecord
from slamtrials.trial import TrialSummary
from slamtrials.trial.exploration import EXPLORATION_KEY, ExplorationMeasures

__all__ = ["FakeTrial"]

_LASER = LaserGeometry(angle_min=-0.1, angle_increment=0.1, range_min=0.0, range_max=10.0)


@dataclass(frozen=True)
class FakeTrial:
    """``FakeTrial(...)(world, config, seed) -> RunRecord`` with per-run errors of a known distribution.

    Attributes
    ----------
    mean_t, std_t:
        Mean and standard deviation of the per-run translational error ``e_t`` (m).
    mean_r, std_r:
        Mean and standard deviation of the per-run rotational error ``e_r`` (rad).
    sleep:
        Wall-clock seconds to pretend to work (for crash and speed-up tests).
    map_offset:
        ``(x m, y m, theta rad)``: the pose of the world frame in the map frame of the estimate.
    cost:
        A cost every run records (:class:`~slamtrials.cost.RunCost`), for tests of how costs are kept and
        reported; None: no cost, as runs of earlier versions.
    exploration:
        Exploration measures every run records (:class:`~slamtrials.trial.exploration.ExplorationMeasures`),
        for tests of how they are kept and reported; None: none, as runs of earlier versions.
    """

    mean_t: float = 0.3
    std_t: float = 0.05
    mean_r: float = 0.05
    std_r: float = 0.01
    sleep: float = 0.0
    map_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    cost: RunCost | None = None
    exploration: ExplorationMeasures | None = None

    def errors(self, seed: int) -> tuple[float, float]:
        """The ``(e_t, e_r)`` (m, rad) that the run with ``seed`` has."""
        rng = np.random.default_rng(int(seed))
        z = rng.standard_normal(2)
        return max(self.mean_t + self.std_t * float(z[0]), 0.0), max(self.mean_r + self.std_r * float(z[1]), 0.0)

    def __call__(self, world, config, seed: int) -> RunRecord:
        if self.sleep > 0:
            time.sleep(self.sleep)
        e_t, e_r = self.errors(seed)
        t = np.array([0.0, 1.0])
        truth = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        estimate = np.array([[0.0, 0.0, 0.0], [1.0 + e_t, 0.0, e_r]])
        if any(self.map_offset):
            estimate = compose(np.asarray(self.map_offset, dtype=np.float64), estimate)
        record = RunRecord(
            t=t,
            scans=np.full((2, 3), 5.0, dtype=np.float32),
            odometry=truth.copy(),
            truth=truth,
            stalled=np.zeros(2, dtype=bool),
            laser=_LASER,
        )
        record.estimate = estimate
        record.map = OccupancyGrid(np.zeros((4, 4), dtype=np.int8), 0.5, np.zeros(3))
        record.metadata = {
            "world": getattr(world, "name", "world"),
            "seed": int(seed),
            "trial": TrialSummary(
                termination_reason="fake",
                mapped_fraction=1.0,
                mapped_fraction_global=1.0,
                observed_fraction=1.0,
                reachable_area_m2=1.0,
                mapped_fraction_connected=1.0,
                connected_free_area_m2=1.0,
                mapped_free_area_m2=1.0,
                distance_m=1.0,
                turning_rad=0.0,
                duration_s=1.0,
                wall_time_s=self.sleep,
                realtime_factor=1.0,
                slam_updates=1,
                slam_seconds=0.0,
                stalled_frames=0,
            ).to_dict(),
        }
        if self.cost is not None:
            record.metadata[COST_KEY] = self.cost.to_dict()
        if self.exploration is not None:
            record.metadata[EXPLORATION_KEY] = self.exploration.to_dict()
        return record
