"""The main job until the campaign exists: scripted tours through bundled worlds, recorded and pictured.

For each world: an automatic tour (:func:`slamtrials.sim.tour.tour_waypoints`) driven by the simulator
with the paper's robot, laser and odometry; the run folder is written under
``<out>/runs/<world>/000/`` as in DESIGN.md, with a picture of the true and odometry paths.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["DEMO_WORLDS", "DemoRun", "run_demo"]

#: Small bundled worlds of different kinds, each explored in well under a minute.
DEMO_WORLDS = ("office_small_01", "lab_small_01")


@dataclass(frozen=True)
class DemoRun:
    """Summary of one demo run: where it is and how it went."""

    world: str
    folder: Path
    frames: int
    simulated_s: float
    wall_s: float
    distance_m: float
    odometry_drift_m: float
    outcome: str


def run_demo(
    out: str | Path,
    worlds: Sequence[str] = DEMO_WORLDS,
    *,
    seed: int = 1,
    on_run: Callable[[DemoRun], None] | None = None,
) -> list[DemoRun]:
    """Drive a tour through each of ``worlds`` and write its run folder and picture under ``out``.

    Returns one :class:`DemoRun` per world; ``on_run`` is called after each (for progress output).
    """
    from slamtrials.geometry import compose
    from slamtrials.io.runfolder import write_run
    from slamtrials.report.runplot import save_run_figure
    from slamtrials.sim import SimConfig, simulate_waypoints
    from slamtrials.sim.tour import tour_waypoints
    from slamtrials.worlds import load_world

    out = Path(out)
    runs = []
    for name in worlds:
        world = load_world(name)
        waypoints = tour_waypoints(world)
        started = time.perf_counter()
        record = simulate_waypoints(world, waypoints, SimConfig.paper(), seed=seed)
        wall = time.perf_counter() - started
        record.metadata.update(world_source=name, wall_time_s=round(wall, 3))
        folder = write_run(out / "runs" / world.name / "000", record)
        save_run_figure(world, record, folder / "run.png", title=f"{world.name}: scripted tour, seed {seed}")
        steps = np.linalg.norm(np.diff(record.truth[:, :2], axis=0), axis=1)
        odometry_end = compose(record.truth[0], record.odometry[-1])
        run = DemoRun(
            world=world.name,
            folder=folder,
            frames=len(record),
            simulated_s=float(record.t[-1] - record.t[0]),
            wall_s=wall,
            distance_m=float(steps.sum()),
            odometry_drift_m=float(np.linalg.norm(odometry_end[:2] - record.truth[-1, :2])),
            outcome=str(record.metadata.get("outcome", "")),
        )
        runs.append(run)
        if on_run is not None:
            on_run(run)
    return runs
