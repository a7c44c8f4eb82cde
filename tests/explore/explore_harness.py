"""Drive the explorer in the real simulator on a "perfect SLAM" map (built from the true poses).

Used by the end-to-end test and, as a script, to try the explorer on several worlds:

    .venv/bin/python tests/explore/explore_harness.py office_small_01 /work/shared/worlds/real/intel_lab/map.yaml

The map is a :class:`~slamtrials.slam.gridmap.GridMap` fed with the true pose, so it lives in the world
frame; coverage compares it with the world's reachable free cells in world coordinates.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

import numpy as np

from slamtrials.explore import (
    ExploreConfig,
    Explorer,
    GridFrame,
    SnapshotTermination,
    TerminationConfig,
)
from slamtrials.sim import SimConfig, Simulator
from slamtrials.slam.gridmap import GridMap
from slamtrials.worlds import load_world
from slamtrials.worlds.world import World, cell_to_world


@dataclass
class HarnessResult:
    world: str
    reason: str
    sim_time: float
    wall_time: float
    coverage: float
    reachable_area: float
    stats: dict = field(default_factory=dict)
    collisions: int = 0
    explorer: Explorer | None = None
    occupancy: object = None

    def line(self) -> str:
        s = self.stats
        return (
            f"{self.world:24s} {self.reachable_area:8.0f} m2  {self.reason:14s} sim {self.sim_time:7.0f} s  "
            f"wall {self.wall_time:6.1f} s  cov {100 * self.coverage:5.1f} %  plans {s['replans']:4d} "
            f"({s['plan_seconds']:.1f} s)  reached {s['goals_reached']:3d}  black {s['goals_blacklisted']:3d}  "
            f"recov {s['recoveries']:3d}  resets {s['blacklist_resets']}  bumps {self.collisions}"
        )


def coverage(world: World, occupancy) -> tuple[float, float]:
    """(fraction of the world's reachable free cells mapped free, reachable free area m^2)."""
    reach = world.reachable_free()
    rows, cols = np.nonzero(reach)
    xy = cell_to_world(world, rows, cols)
    frame = GridFrame.of(occupancy)
    r, c = frame.to_cell(xy)
    inside = (r >= 0) & (r < frame.height) & (c >= 0) & (c < frame.width)
    grid = occupancy.grid
    mapped = np.zeros(len(rows), dtype=bool)
    mapped[inside] = (grid[r[inside], c[inside]] >= 0) & (grid[r[inside], c[inside]] < 50)
    return float(mapped.mean()), float(reach.sum()) * world.resolution**2


def run(
    world: World,
    *,
    seed: int = 0,
    max_time: float = 10800.0,
    integrate_every: int = 2,
    map_every: int = 5,
    explore: ExploreConfig | None = None,
    termination: TerminationConfig | None = None,
) -> HarnessResult:
    started = time.perf_counter()
    sim = Simulator(world, SimConfig.paper(), np.random.default_rng(seed))  # the paper's noise-free laser
    laser = sim.laser
    gridmap = GridMap(0.05)
    frame = sim.observe()
    gridmap.integrate_frame(frame.truth, frame.ranges, laser)
    occupancy = gridmap.occupancy()
    explorer = Explorer(explore)
    # the environment's size class comes from the world, as the paper classified its buildings a priori
    _, area = coverage(world, occupancy)
    term = SnapshotTermination(termination or TerminationConfig(max_time=max_time), area=area)
    steps = 0
    bumps = 0
    reason = None
    while True:
        reason = term.check(frame.t, occupancy)
        if reason is not None:
            break
        if explorer.done:
            reason = explorer.reason
            break
        v, w = explorer.command(frame.t, frame.truth, frame.ranges, laser, occupancy, stalled=frame.stalled)
        frame = sim.step((v, w))
        bumps += int(frame.stalled)
        steps += 1
        if steps % integrate_every == 0:
            gridmap.integrate_frame(frame.truth, frame.ranges, laser)
        if steps % map_every == 0:
            occupancy = gridmap.occupancy()
    gridmap.integrate_frame(frame.truth, frame.ranges, laser)
    occupancy = gridmap.occupancy()
    cov, area = coverage(world, occupancy)
    stats = dict(vars(explorer.stats))
    return HarnessResult(
        world.name, str(reason), frame.t, time.perf_counter() - started, cov, area, stats, bumps, explorer, occupancy
    )


def main(argv: list[str]) -> None:
    for source in argv:
        world = load_world(source)
        if world.name in ("map", "world"):
            world = World(
                world.occupied, world.resolution, world.origin, source.split("/")[-2], world.start, world.metadata
            )
        result = run(world)
        sys.stdout.write(result.line() + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main(sys.argv[1:])
