"""Running a SLAM algorithm over a recording: the one function behind ``slamtrials slam``, campaign
replays and every other place that feeds recorded frames to an algorithm.

It seeds the algorithm by the convention of :mod:`slamtrials.seeding`, so a recording of a trial run
with the trial's seed gives the trial's own estimate, bit for bit, and measures what the run cost
(:class:`~slamtrials.cost.RunCost`, :mod:`slamtrials.costmeter`). It does no I/O.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from slamtrials.cost import RunCost
from slamtrials.costmeter import CostMeter
from slamtrials.errors import ConfigError
from slamtrials.record import OccupancyGrid, Reading, RunRecord, Trajectory
from slamtrials.seeding import check_seed, slam_rng
from slamtrials.slam.base import ChildProcessAlgorithm, get_algorithm, resolve_config

__all__ = ["SlamRun", "estimate_per_frame", "run_over_recording"]


@dataclass(frozen=True, eq=False)
class SlamRun:
    """What one SLAM run over a recording produced.

    Attributes
    ----------
    algorithm:
        Registry name.
    preset:
        Preset applied, or None.
    config:
        The resolved configuration (the algorithm's validated ``Config``).
    seed:
        The run's seed (the algorithm's stream is :func:`slamtrials.seeding.slam_rng` of it).
    trajectory:
        The algorithm's :meth:`trajectory` after the last frame (map frame).
    online:
        float64 ``[T, 3]``: what ``process`` returned for each frame (map frame).
    occupancy:
        The final map.
    timing:
        float64 ``[T]`` wall-clock seconds of each ``process`` call.
    updates:
        The algorithm's update count after the last frame.
    cost:
        CPU time and peak memory of the algorithm and of the whole run, and the time per update
        (:class:`~slamtrials.cost.RunCost`); None where unknown (keyword only).
    """

    algorithm: str
    preset: str | None
    config: BaseModel
    seed: int
    trajectory: Trajectory
    online: NDArray[np.float64]
    occupancy: OccupancyGrid
    timing: NDArray[np.float64]
    updates: int
    cost: RunCost | None = field(default=None, kw_only=True)

    def estimate_per_frame(self, record: RunRecord) -> NDArray[np.float64]:
        """float64 ``[T, 3]``: the estimate at each frame of ``record`` (see :func:`estimate_per_frame`)."""
        return estimate_per_frame(self.algorithm, self.trajectory, record)


def estimate_per_frame(algorithm: str, trajectory: Trajectory, record: RunRecord) -> NDArray[np.float64]:
    """float64 ``[T, 3]``: algorithm ``algorithm``'s ``trajectory``, which must hold one pose per frame of ``record``.

    Raises
    ------
    ConfigError
        The trajectory does not hold one pose per frame at the frames' times.
    """
    if len(trajectory) != len(record) or not np.array_equal(trajectory.t, record.t):
        raise ConfigError(
            f"SLAM algorithm {algorithm!r} returned {len(trajectory)} poses for {len(record)} frames; "
            "trajectory() must hold one pose per processed frame"
        )
    return trajectory.poses


def run_over_recording(
    record: RunRecord,
    algorithm: str,
    *,
    preset: str | None = None,
    overrides: dict[str, Any] | None = None,
    seed: int = 0,
    on_frame: Callable[[int, int], None] | None = None,
) -> SlamRun:
    """Process every frame of ``record`` with algorithm ``algorithm``.

    Parameters
    ----------
    record:
        The recording (a trial's run, a simulated tour, a real log or bag).
    algorithm:
        Registry or entry-point name.
    preset, overrides:
        Configuration (see :func:`slamtrials.slam.resolve_config`).
    seed:
        The run's seed; the algorithm is reset with :func:`slamtrials.seeding.slam_rng` of it, as in a trial.
    on_frame:
        Called as ``on_frame(index, total)`` after each frame (for progress bars).

    Raises
    ------
    ConfigError
        Unknown algorithm, preset or parameter, a bad value, a negative seed or a recording without frames.
    """
    seed = check_seed(seed)
    if len(record) == 0:
        raise ConfigError("the recording has no frames")
    cls = get_algorithm(algorithm)
    config = resolve_config(cls, preset=preset, overrides=overrides)
    meter = CostMeter()  # reads clocks and the kernel's memory counters: nothing flows back into the run
    mark = meter.enter()
    slam = cls(config, record.laser)
    slam.reset(slam_rng(seed))
    meter.leave(mark)
    total = len(record)
    timing = np.empty(total, dtype=np.float64)
    online = np.empty((total, 3), dtype=np.float64)
    for k in range(total):
        frame = Reading(t=float(record.t[k]), ranges=record.scans[k], odometry=record.odometry[k])
        updates = slam.updates
        mark = meter.enter()
        started = time.perf_counter()
        online[k] = slam.process(frame)
        timing[k] = time.perf_counter() - started
        meter.leave(mark, update_seconds=float(timing[k]) if slam.updates > updates else None)
        if on_frame is not None:
            on_frame(k, total)
    mark = meter.enter()
    trajectory = slam.trajectory()
    occupancy = slam.occupancy()
    meter.leave(mark)
    return SlamRun(
        algorithm=algorithm,
        preset=preset,
        config=config,
        seed=seed,
        trajectory=trajectory,
        online=online,
        occupancy=occupancy,
        timing=timing,
        updates=int(slam.updates),
        cost=meter.finish(slam.child_usage(), in_child=True)
        if isinstance(slam, ChildProcessAlgorithm)  # a program online: its cost is its process's
        else meter.finish(),
    )
