"""Where a trial's time goes: one trial under cProfile, the functions with the most time.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/profile_trial.py --world school_medium_01 --seed 2
[--algorithm karto] [--profile realistic] [--top 25]``.

The trial is the paper's set-up with ``--algorithm`` online (``gmapping``: its ``paper`` preset; others:
their defaults), after a warm-up trial on a tiny world so that numba's compilation is not counted.
Printed: process CPU time, the functions sorted by cumulative and by own time (a numba kernel is one
call: its time is all its own), and, for karto, its per-node times and optimizer runs.
cProfile adds a fixed cost per Python call, so the shares of Python-heavy code are overstated a little.
"""

from __future__ import annotations

import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_trial

import argparse  # noqa: E402
import cProfile  # noqa: E402
import pstats  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from bench_trial import resolve, trial_config  # noqa: E402


def main() -> None:
    import slamtrials.trial.run as trial_run
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="school_medium_01")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--algorithm", default="karto")
    parser.add_argument("--profile", default="paper", help="the simulator's error profile")
    parser.add_argument("--top", type=int, default=25)
    args = parser.parse_args()

    config = trial_config(args.algorithm, args.profile)
    trial_run.run_trial(load_world("house_small_01"), config, 0)  # compiles every kernel
    caught = []
    original = trial_run.get_algorithm

    def catching(name):
        cls = original(name)

        def build(*a, **k):
            caught.append(cls(*a, **k))
            return caught[-1]

        return build

    trial_run.get_algorithm = catching
    world = load_world(resolve(args.world))
    profiler = cProfile.Profile()
    cpu = time.process_time()
    profiler.enable()
    info = trial_run.run_trial(world, config, args.seed).metadata["trial"]
    profiler.disable()
    cpu = time.process_time() - cpu
    print(
        f"{world.name} seed {args.seed} {args.algorithm}: {info['duration_s']:.0f} s simulated, CPU {cpu:.1f} s "
        f"(profiled), {info['slam_updates']} updates, SLAM {info['slam_seconds']:.1f} s, planning "
        f"{info['explorer']['plan_seconds']:.1f} s, wall {info['wall_time_s']:.1f} s"
    )
    stats = pstats.Stats(profiler)
    stats.sort_stats("cumulative").print_stats(args.top)
    stats.sort_stats("tottime").print_stats(args.top)
    slam = caught[-1]
    if hasattr(slam, "timings") and slam.timings:
        node_ms = 1000.0 * np.array([seconds for _, seconds in slam.timings])
        print(
            f"nodes {len(node_ms)}: total {node_ms.sum() / 1e3:.1f} s, median {np.median(node_ms):.1f} ms, "
            f"p90 {np.percentile(node_ms, 90):.1f} ms, max {node_ms.max():.0f} ms; loop closures {slam.loop_closures}"
        )
        runs = np.array([(n, e, s, i) for n, e, s, i in slam.optimizations]) if slam.optimizations else None
        if runs is not None:
            print(
                f"optimizer: {len(runs)} runs, {runs[:, 2].sum():.2f} s in all; largest graph {int(runs[:, 0].max())} "
                f"nodes / {int(runs[:, 1].max())} edges, slowest run {1000 * runs[:, 2].max():.0f} ms"
            )


if __name__ == "__main__":
    main()
