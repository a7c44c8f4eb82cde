"""Trial speed: wall time of one complete trial on one core, and the simulated-to-wall-time ratio.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_trial.py [--worlds NAME ...] [--seed 1]
[--seeds 1 2 3] [--profiles paper realistic]``.

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

Error profiles (issue 21, item 8): ``--profiles paper realistic --seeds 1 2 3`` runs every world with
each profile and seed, interleaved (world, seed, then the profiles in turn, so that a change in the
machine's load hits both alike), and adds a table per world: mean wall and simulated time per
profile, how the trials ended, the mapped free share of the reachable area, and the ratio of each
profile's mean wall time to the first profile's. *Mapped free* is the share of the world's reachable
cells that the final SLAM map calls free (carried into the map through the nearest trajectory pose,
as ``mapped_fraction``, but not counting cells the map calls occupied): unlike ``mapped_fraction`` it
is not fooled by the free space GMapping draws beyond the walls from beams without a return. Each
trial's progress line ends with a digest of its true and estimated paths (the same digest, the same
run, bit for bit).
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
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
    parser.add_argument("--seed", type=int, default=1, help="seed of every trial (unless --seeds)")
    parser.add_argument("--seeds", type=int, nargs="+", help="several seeds per world and profile")
    parser.add_argument(
        "--profiles", nargs="+", default=["paper"], help="simulator error profiles, run interleaved (first = reference)"
    )
    args = parser.parse_args()
    seeds = args.seeds or [args.seed]

    started = time.perf_counter()
    run_trial(load_world("house_small_01"), None, 0)  # compiles every kernel
    run_trial(load_world("house_small_01"), _config(args.profiles[-1]), 0)  # and the error models' kernels
    print(f"warm-up trials (with compilation): {time.perf_counter() - started:.0f} s", flush=True)
    rows = []
    for name in args.worlds:
        world = load_world(resolve(name))
        for seed in seeds:
            for profile in args.profiles:
                load = os.getloadavg()[0]
                record = run_trial(world, _config(profile), seed)
                info = record.metadata["trial"]
                free = mapped_free_fraction(world, record)
                rows.append((world.name, profile, seed, info, free, load))
                digest = hashlib.sha256(record.truth.tobytes() + record.estimate.tobytes()).hexdigest()[:16]
                print(
                    f"{world.name} {profile} seed {seed}: {info['termination_reason']} after {info['duration_s']:.1f} s "
                    f"simulated in {info['wall_time_s']:.1f} s, {info['slam_updates']} updates, mapped free {free:.3f}, "
                    f"load {load:.1f}, run digest {digest}",
                    flush=True,
                )

    print(
        f"\n- Machine: {os.cpu_count()} cores, CPU `{cpu_model()}`; one trial at a time, NUMBA_NUM_THREADS=1; "
        f"date {time.strftime('%Y-%m-%d')}; seeds {' '.join(map(str, seeds))}; profiles {' '.join(args.profiles)}"
    )
    print()
    print(
        "| world | profile | seed | reachable m^2 | end | mapped | mapped free | simulated s | wall s | sim/wall | updates "
        "| SLAM ms per update | SLAM share | planning share | distance m | turning rad | load avg |"
    )
    print("|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, profile, seed, info, free, load in rows:
        wall = info["wall_time_s"]
        print(
            f"| {name} | {profile} | {seed} | {info['reachable_area_m2']:,.0f} | {info['termination_reason']} | "
            f"{info['mapped_fraction']:.3f} | {free:.3f} | {info['duration_s']:.0f} | {wall:.1f} | "
            f"{info['realtime_factor']:.1f} | {info['slam_updates']} | "
            f"{1e3 * info['slam_seconds'] / max(info['slam_updates'], 1):.0f} | {info['slam_seconds'] / wall:.0%} | "
            f"{info['explorer']['plan_seconds'] / wall:.0%} | {info['distance_m']:.0f} | {info['turning_rad']:.0f} | {load:.1f} |"
        )
    if len(args.profiles) > 1:
        _profile_summary(rows, args.profiles)


def _config(profile: str):  # noqa: ANN202 - TrialConfig, imported late
    from slamtrials.trial import TrialConfig

    return TrialConfig.model_validate({"sim": {"profile": profile}})


def mapped_free_fraction(world, record) -> float:  # noqa: ANN001 - World, RunRecord
    """Share of the world's reachable cells that the final SLAM map calls free (module docstring)."""
    import numpy as np

    from slamtrials.record import OccupancyGrid
    from slamtrials.trial.coverage import local_mapped_fraction

    final = record.map
    free_only = np.where((final.grid >= 0) & (final.grid < 50), 0, -1).astype(np.int8)
    reachable = world.reachable_by_disc(record.metadata["config"]["sim"]["robot"]["radius"])
    return local_mapped_fraction(
        world, OccupancyGrid(free_only, final.resolution, final.origin), record.estimate, record.truth, reachable
    )


def _profile_summary(rows: list, profiles: list[str]) -> None:
    """Per world: mean wall and simulated time of each profile, ends, mapped free share, wall-time ratio."""
    print()
    print(
        "| world | profile | trials | ends | mean simulated s | mean wall s | mean mapped free | wall / "
        + profiles[0]
        + " |"
    )
    print("|---|---|---:|---|---:|---:|---:|---:|")
    worlds = list(dict.fromkeys(row[0] for row in rows))
    for name in worlds:
        reference = None
        for profile in profiles:
            mine = [row for row in rows if row[0] == name and row[1] == profile]
            wall = sum(row[3]["wall_time_s"] for row in mine) / len(mine)
            sim = sum(row[3]["duration_s"] for row in mine) / len(mine)
            free = sum(row[4] for row in mine) / len(mine)
            ends: dict[str, int] = {}
            for row in mine:
                ends[row[3]["termination_reason"]] = ends.get(row[3]["termination_reason"], 0) + 1
            reference = wall if reference is None else reference
            end_text = ", ".join(f"{k} {v}" for k, v in sorted(ends.items()))
            print(
                f"| {name} | {profile} | {len(mine)} | {end_text} | {sim:.0f} | {wall:.1f} | {free:.3f} | "
                f"{wall / reference:.2f} |"
            )


if __name__ == "__main__":
    main()
