"""Trial speed: wall time of one complete trial on one core, and the simulated-to-wall-time ratio.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_trial.py [--worlds NAME ...] [--seed 1]``.

Each world gets one trial with the paper's set-up (:func:`slamtrials.trial.run_trial` defaults: online
GMapping ``paper`` preset, the frontier explorer, the paper's termination rule), in this process, after a
warm-up trial on a tiny world so that numba's compilation is not counted. Reported per world: the free
area the robot can reach, how the trial ended, simulated and wall time, their ratio (the paper's system
ran in real time: ratio 1), GMapping updates and their mean cost, the share of the wall time spent in
SLAM and in planning, distance and turning. The target of issue 6: a world of about 1,000 m^2 in at most
60 s of wall time on one core.

Default worlds: office_small_01 (small, 153 m^2), mit_building31 and school_medium_01 (about
1,000 m^2; the first from ``../shared/worlds/real``), lab_large_01 (large, 3,092 m^2). Names are
catalog names, real-world folder names under ``$SLAMTRIALS_SHARED/worlds/real``, or map files.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", HERE.parent.parent / "shared"))
DEFAULT_WORLDS = ("office_small_01", "mit_building31", "school_medium_01", "lab_large_01")


def resolve(name: str) -> str:
    """A catalog name, a real-world folder name or a path, as :func:`load_world` takes it."""
    folder = SHARED / "worlds" / "real" / name
    if (folder / "map.yaml").is_file():
        return str(folder / "map.yaml")
    return name


def main() -> None:
    from slamtrials.trial import run_trial
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=list(DEFAULT_WORLDS))
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()

    started = time.perf_counter()
    run_trial(load_world("house_small_01"), None, 0)  # compiles every kernel
    print(f"warm-up trial (with compilation): {time.perf_counter() - started:.0f} s", flush=True)
    rows = []
    for name in args.worlds:
        world = load_world(resolve(name))
        load = os.getloadavg()[0]
        info = run_trial(world, None, args.seed).metadata["trial"]
        rows.append((world.name, info, load))
        print(f"{world.name}: {info['duration_s']:.0f} s simulated in {info['wall_time_s']:.0f} s", flush=True)

    print(
        f"\n- Machine: {os.cpu_count()} cores, CPU `{cpu_model()}`; one trial at a time, NUMBA_NUM_THREADS=1; "
        f"date {time.strftime('%Y-%m-%d')}; seed {args.seed}"
    )
    print()
    print(
        "| world | reachable m^2 | end | mapped | simulated s | wall s | sim/wall | updates | SLAM ms per update "
        "| SLAM share | planning share | distance m | turning rad | load avg |"
    )
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, info, load in rows:
        wall = info["wall_time_s"]
        print(
            f"| {name} | {info['reachable_area_m2']:,.0f} | {info['termination_reason']} | {info['mapped_fraction']:.3f} | "
            f"{info['duration_s']:.0f} | {wall:.0f} | {info['realtime_factor']:.1f} | {info['slam_updates']} | "
            f"{1e3 * info['slam_seconds'] / max(info['slam_updates'], 1):.0f} | {info['slam_seconds'] / wall:.0%} | "
            f"{info['explorer']['plan_seconds'] / wall:.0%} | {info['distance_m']:.0f} | {info['turning_rad']:.0f} | {load:.1f} |"
        )


if __name__ == "__main__":
    main()
