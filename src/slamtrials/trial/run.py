"""One trial: the simulated robot explores a world on its own, mapped online by a SLAM algorithm.

Per simulator step (``sim.dt``, 0.1 s by default): the frame goes to the SLAM algorithm, which returns
its pose estimate; the termination rule looks at the SLAM map; the explorer turns the estimate, the scan
and the map into a velocity command; the simulator steps. The trial ends when

* ``map_converged``: two consecutive map snapshots differ by less than the MSE threshold (the paper's
  rule);
* ``max_snapshots``: ``termination.max_snapshots`` snapshots were taken (the paper's limit, about 19);
* ``no_frontiers``: the explorer has no reachable frontier left;
* ``time_cap``: the hard cap on simulated time was reached.

Seeds: the trial's seed feeds a ``numpy.random.SeedSequence``; its first child drives the simulator
(odometry bias and any sensor noise), its second the SLAM algorithm. The explorer draws nothing. The
same world, config and seed give the same run, bit for bit.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from slamtrials import stablemath
from slamtrials.cost import COST_KEY
from slamtrials.costmeter import CostMeter
from slamtrials.errors import ConfigError
from slamtrials.explore import Explorer, SnapshotTermination
from slamtrials.record import Frame, OccupancyGrid, RunRecord
from slamtrials.seeding import check_seed, run_streams
from slamtrials.sim import Simulator
from slamtrials.slam import ChildProcessAlgorithm, get_algorithm
from slamtrials.trial.config import TrialConfig
from slamtrials.trial.coverage import (
    known_cells,
    known_free_area,
    known_share,
    local_map_points,
    mapped_fraction,
    observed_fraction,
)
from slamtrials.trial.exploration import EXPLORATION_KEY, ExplorationMeasures, exploration_measures
from slamtrials.trial.firstknown import FirstKnown, coverage_curve, sample_period
from slamtrials.trial.summary import TrialSummary
from slamtrials.worlds import World

__all__ = ["run_trial", "TrialProgress"]


@dataclass(frozen=True)
class TrialProgress:
    """What a progress callback is told, every ``progress_period`` seconds of simulated time.

    Attributes
    ----------
    t:
        Simulated time (s).
    max_time:
        The hard cap on simulated time (s).
    known_free_area:
        Free area of the current SLAM map (m^2).
    reachable_area:
        Reachable free area of the true world (m^2).
    slam_updates:
        Map (filter) updates the SLAM algorithm has done so far.
    """

    t: float
    max_time: float
    known_free_area: float
    reachable_area: float
    slam_updates: int = 0


def _path_length(truth: np.ndarray) -> float:
    return float(np.sum(stablemath.hypot(np.diff(truth[:, 0]), np.diff(truth[:, 1]))))


def _exploration(
    history: FirstKnown,
    points: NDArray[np.float64],
    known: NDArray[np.bool_],
    record: RunRecord,
    reason: str,
) -> ExplorationMeasures:
    """The run's exploration measures: the coverage at each of ``history``'s samples (the reachable cells
    carried into the map frame, ``points`` ``[K, 2]``, that the final map knows, ``known`` ``[K]``), at the
    samples' simulated times and distances along the true path."""
    frames = np.array(history.frames, dtype=np.intp)
    steps = stablemath.hypot(np.diff(record.truth[:, 0]), np.diff(record.truth[:, 1]))
    along = np.concatenate([[0.0], np.cumsum(steps)])  # [T] m, the true path's length up to each frame
    curve = coverage_curve(history.first_sample(points), known, len(frames))
    return exploration_measures(record.t[frames] - record.t[0], curve, along[frames], reason)


def _turning(truth: np.ndarray) -> float:
    """Total absolute heading change (rad) of poses ``[N, 3]``."""
    return float(np.sum(np.abs(np.remainder(np.diff(truth[:, 2]) + np.pi, 2.0 * np.pi) - np.pi)))


def run_trial(
    world: World,
    config: TrialConfig | None = None,
    seed: int = 0,
    *,
    on_progress: Callable[[TrialProgress], None] | None = None,
    progress_period: float = 10.0,
) -> RunRecord:
    """Explore ``world`` once with online SLAM and return the run.

    Parameters
    ----------
    world:
        The world; the robot starts at ``world.start``.
    config:
        The trial's settings; ``None`` means :class:`TrialConfig` defaults (the paper's set-up
        with the default error profile, ``realistic``).
    seed:
        Non-negative seed of every random draw of the trial.
    on_progress:
        Called with a :class:`TrialProgress` every ``progress_period`` seconds of simulated time.

    Returns
    -------
    RunRecord
        Every frame (``t``, ``scans``, ``odometry``, ``truth``, ``stalled``), ``estimate`` (the SLAM
        trajectory, map frame, one pose per frame), ``online`` (what SLAM returned at each frame, the
        pose the explorer drove by), ``map`` (the final SLAM map), and ``metadata``:
        ``trial`` (termination reason, mapped and observed fractions of the free area the robot's
        footprint can reach (:meth:`World.reachable_by_disc`; mapped with the SLAM map aligned locally,
        :func:`~slamtrials.trial.coverage.local_mapped_fraction`, and, as ``mapped_fraction_global``,
        through the first pose only), the mapped fraction and area of all free space connected to the
        start, distance travelled, total turning of the true heading, simulated
        duration, wall time, SLAM updates and the wall time spent in SLAM, explorer counters, snapshot
        MSEs), ``exploration`` (:class:`~slamtrials.trial.exploration.ExplorationMeasures`: time and distance
        to 90 % and 99 % coverage, the coverage curve, the termination reason), ``seed``, ``world``, the drawn
        odometry ``bias``, the resolved ``config``, and ``cost``: what
        the run cost (:class:`~slamtrials.cost.RunCost`: CPU time and peak memory of SLAM and of the whole
        run, time per SLAM update), a measurement of the machine that no result depends on.

    Raises
    ------
    ConfigError
        A bad seed or SLAM configuration.
    SimulationError
        The robot does not fit at the world's start pose.
    """
    streams = run_streams(check_seed(seed, "trial seed"))
    config = TrialConfig() if config is None else config
    config.slam.check_online()
    slam_config = config.slam.resolved()
    started = time.perf_counter()
    meter = CostMeter()  # reads clocks and the kernel's memory counters: nothing flows back into the run

    sim = Simulator(world, config.sim, np.random.default_rng(streams.simulator))
    laser = sim.laser
    mark = meter.enter()
    slam = get_algorithm(config.slam.algorithm)(slam_config, laser)
    slam.reset(np.random.default_rng(streams.slam))
    meter.leave(mark)
    explorer = Explorer(config.explore, config.robot_limits())
    reachable = world.reachable_by_disc(config.sim.robot.radius)
    reachable_area = world.area_of(reachable)
    # the paper chose the snapshot period by the building's size, known in advance
    termination = SnapshotTermination(config.termination, area=reachable_area)
    max_time = config.termination.max_time

    frames: list[Frame] = []
    online: list[NDArray[np.float64]] = []
    history = FirstKnown()  # when the maps first knew each place: the coverage curve
    next_sample = -np.inf
    frame = sim.observe()
    next_report = 0.0
    reason = None
    slam_seconds = 0.0
    while True:
        frames.append(frame)
        updates = slam.updates
        mark = meter.enter()
        tick = time.perf_counter()
        estimate = slam.process(frame.reading())  # the algorithm never sees the truth
        spent = time.perf_counter() - tick
        slam_seconds += spent
        online.append(np.array(estimate, dtype=np.float64))
        grid = slam.occupancy()
        meter.leave(mark, update_seconds=spent if slam.updates > updates else None)
        if frame.t >= next_sample and grid is not history.last_map:
            history.update(len(frames) - 1, grid)
            next_sample = frame.t + sample_period(grid)
        reason = termination.check(frame.t, grid)
        if reason is not None:
            break
        command = explorer.command(frame.t, estimate, frame.ranges, laser, grid)
        if explorer.done:
            reason = explorer.reason or "no_frontiers"
            break
        if on_progress is not None and frame.t >= next_report:
            on_progress(TrialProgress(frame.t, max_time, known_free_area(grid), reachable_area, int(slam.updates)))
            next_report = frame.t + progress_period
        frame = sim.step(command)

    record = RunRecord.from_frames(frames, laser)
    mark = meter.enter()
    trajectory = slam.trajectory()
    if len(trajectory) != len(record) or not np.array_equal(trajectory.t, record.t):
        raise ConfigError(
            f"SLAM algorithm {config.slam.algorithm!r} returned {len(trajectory)} poses for "
            f"{len(record)} frames; trajectory() must hold one pose per processed frame"
        )
    record.estimate = trajectory.poses
    record.online = np.stack(online)
    final_map: OccupancyGrid = slam.occupancy()
    meter.leave(mark)
    record.map = final_map
    if not (history.frames and history.frames[-1] == len(record) - 1 and history.last_map is final_map):
        history.update(len(record) - 1, final_map)  # the final map is the last sample
    wall = time.perf_counter() - started
    duration = float(record.t[-1] - record.t[0])
    stats = explorer.stats
    points = local_map_points(world, record.estimate, record.truth, reachable, config.coverage_stride)
    known = known_cells(final_map, points)
    summary = TrialSummary(
        termination_reason=reason,
        mapped_fraction=known_share(known),
        mapped_fraction_global=mapped_fraction(world, final_map, record.estimate[0], record.truth[0], reachable),
        observed_fraction=observed_fraction(
            world, record.truth, record.scans, laser, config.coverage_stride, reachable
        ),
        reachable_area_m2=reachable_area,
        mapped_fraction_connected=mapped_fraction(world, final_map, record.estimate[0], record.truth[0]),
        connected_free_area_m2=world.area_of(world.reachable_free()),
        mapped_free_area_m2=known_free_area(final_map),
        distance_m=_path_length(record.truth),
        turning_rad=_turning(record.truth),
        duration_s=duration,
        wall_time_s=wall,
        realtime_factor=duration / max(wall, 1e-9),
        slam_updates=int(slam.updates),
        slam_seconds=slam_seconds,
        stalled_frames=int(np.count_nonzero(record.stalled)),
        explorer={k: (round(v, 3) if isinstance(v, float) else v) for k, v in vars(stats).items()},
        snapshots=tuple((round(t, 3), round(mse, 4)) for t, mse in termination.history),
    )
    if isinstance(slam, ChildProcessAlgorithm):  # an external program: its cost is its process's
        cost = meter.finish(slam.child_usage(), in_child=True)
    else:
        cost = meter.finish()
    record.metadata = {
        **sim.metadata,
        "seed": int(seed),
        "trial": summary.to_dict(),
        EXPLORATION_KEY: _exploration(history, points, known, record, reason).to_dict(),
        "config": config.model_dump(mode="json"),
        "slam_config": slam_config.model_dump(mode="json"),
        COST_KEY: cost.to_dict(),
    }
    return record
