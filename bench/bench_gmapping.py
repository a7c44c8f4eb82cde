"""Benchmark of ``gmapping``: time of one filter update, its particles x beams scaling, and memory.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_gmapping.py [--quick]`` (``make bench`` runs all
benchmarks). Prints Markdown tables; the latest figures are kept in bench/RESULTS.md ("GMapping").

1. One filter update (motion model, scan matching, weighing, resampling when due, registration) with
   the ``paper`` preset (40 particles, 541 beams of 30 m) in a realistic map: a seeded tour of the
   bundled world ``office_medium_01``. The filter first processes the first half of the tour, so the
   particles' maps hold what a robot half-way through sees; then the next updates are timed one by one.
   The published map (rebuilt every 5 s) is timed separately, as its cost per update.
2. Scaling: the same tour re-simulated with lasers of 135, 271, 541 and 1081 beams (270 deg), filters
   of 10, 20, 40 and 80 particles; median update time of each pair.
3. Memory: the ``paper`` filter over a tour of the largest bundled world (``multiwing_large_01``, about
   9,900 m^2 of floor): peak bytes of the particles' tile maps and the process's peak resident size.

Compile time is excluded (a warm-up run first). spec/gmapping.md gives the C++ original's times on
this kind of machine: about 240 ms per update for 40 particles x 541 beams.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import resource  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from benchutil import cpu_model
from slamtrials.record import Frame, RunRecord  # noqa: E402
from slamtrials.sim import SimConfig  # noqa: E402
from slamtrials.sim.tour import tour_waypoints  # noqa: E402
from slamtrials.sim.waypoints import simulate_waypoints  # noqa: E402
from slamtrials.slam import make_algorithm  # noqa: E402
from slamtrials.slam.gmapping.kernels import TILE  # noqa: E402
from slamtrials.worlds import load_world  # noqa: E402

SEED = 7
WORLD = "office_medium_01"
LARGEST = "multiwing_large_01"


def tour(world_name: str, beams: int = 541, *, max_time: float = 3600.0) -> RunRecord:
    """A seeded tour of a bundled world with a 270-degree laser of ``beams`` beams."""
    world = load_world(world_name)
    base = SimConfig.paper()
    laser = base.laser.model_copy(update={"angular_resolution": math.radians(270.0) / (beams - 1)})
    config = base.model_copy(update={"laser": laser})
    return simulate_waypoints(world, tour_waypoints(world), config, seed=SEED, max_time=max_time)


def frames(record: RunRecord):
    for k in range(len(record)):
        yield Frame(t=float(record.t[k]), ranges=record.scans[k], odometry=record.odometry[k], truth=record.truth[k])


def update_times(
    record: RunRecord, particles: int, *, warm_fraction: float = 0.5, timed: int = 60, publish: bool = False
) -> tuple[np.ndarray, object]:
    """Seconds of each processed reading after the first ``warm_fraction`` of the run (up to ``timed``)."""
    overrides = {"particles": particles}
    if not publish:
        overrides["map_update_interval"] = 1.0e6  # only the first reading publishes
    slam = make_algorithm("gmapping", record.laser, preset="paper", overrides=overrides)
    slam.reset(np.random.default_rng(SEED))
    warm = int(warm_fraction * len(record))
    times = []
    for k, frame in enumerate(frames(record)):
        before = slam.updates
        started = time.perf_counter()
        slam.process(frame)
        elapsed = time.perf_counter() - started
        if k >= warm and slam.updates > before:
            times.append(elapsed)
            if len(times) >= timed:
                break
    return np.array(times), slam


def single_update(record: RunRecord) -> None:
    times, slam = update_times(record, 40)
    with_map, _ = update_times(record, 40, publish=True)
    print(f"### One filter update: paper preset, 40 particles x 541 beams, {WORLD} (seed {SEED})\n")
    print("| measure | ms |\n|---|---|")
    print(f"| filter update, median of {len(times)} | {1e3 * np.median(times):.1f} |")
    print(f"| filter update, mean | {1e3 * times.mean():.1f} |")
    print(f"| filter update, 90th percentile | {1e3 * np.percentile(times, 90):.1f} |")
    print(f"| with the published map rebuilt every 5 s, mean | {1e3 * with_map.mean():.1f} |")
    print(
        f"\nC++ original (spec/gmapping.md): about 240 ms; speed-up at the median: "
        f"{0.240 / np.median(times):.1f}x. Resamplings so far: {slam.resamplings} in {slam.updates} updates.\n"
    )


def scaling(quick: bool) -> None:
    beam_counts = (135, 271, 541) if quick else (135, 271, 541, 1081)
    particle_counts = (10, 20, 40) if quick else (10, 20, 40, 80)
    print("### Median filter update (ms), particles x beams\n")
    print("| particles | " + " | ".join(f"{b} beams" for b in beam_counts) + " |")
    print("|---|" + "---|" * len(beam_counts))
    records = {b: tour(WORLD, b) for b in beam_counts}
    for n in particle_counts:
        cells = []
        for b in beam_counts:
            times, _ = update_times(records[b], n, timed=30)
            cells.append(f"{1e3 * np.median(times):.1f}")
        print(f"| {n} | " + " | ".join(cells) + " |")
    print()


def memory(quick: bool) -> None:
    record = tour(LARGEST, max_time=600.0 if quick else 3600.0)
    slam = make_algorithm("gmapping", record.laser, preset="paper")
    slam.reset(np.random.default_rng(SEED))
    peak_maps = 0
    peak_tiles = 0
    started = time.perf_counter()
    for frame in frames(record):
        before = slam.updates
        slam.process(frame)
        if slam.updates > before:
            peak_maps = max(peak_maps, slam.maps.nbytes())
            peak_tiles = max(peak_tiles, slam.maps.tiles_in_use)
    elapsed = time.perf_counter() - started
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print(f"### Memory: 40 particles (paper preset) over a {record.t[-1]:.0f} s tour of {LARGEST}\n")
    print("| measure | value |\n|---|---|")
    print(f"| updates | {slam.updates} ({slam.resamplings} resamplings) |")
    print(f"| peak tiles held ({TILE} x {TILE} cells, {TILE * TILE * 12 // 1024} KiB each) | {peak_tiles:,} |")
    print(f"| peak bytes of the particle maps (pool + directories) | {peak_maps / 2**20:.0f} MiB |")
    print(f"| peak resident size of the whole process | {rss / 2**20:.0f} MiB |")
    print(f"| wall time of the run | {elapsed:.0f} s ({record.t[-1] / elapsed:.1f}x real time) |\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer scaling points, a 10-minute memory tour")
    args = parser.parse_args()
    print(f"CPU: {cpu_model()}; NUMBA_NUM_THREADS={os.environ['NUMBA_NUM_THREADS']}\n")
    record = tour(WORLD)
    update_times(record, 4, timed=2)  # compile the kernels
    single_update(record)
    scaling(args.quick)
    memory(args.quick)


if __name__ == "__main__":
    main()
