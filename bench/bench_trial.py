"""Trial speed: wall time of one complete trial on one core, and the simulated-to-wall-time ratio.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_trial.py [--worlds NAME ...] [--seeds 1 ...]
[--algorithms gmapping karto] [--profiles paper realistic]``.

Each world gets one trial with the paper's set-up (:func:`slamtrials.trial.run_trial` defaults: online
GMapping ``paper`` preset, the frontier explorer, the paper's termination rule), in this process, after a
warm-up trial on a tiny world so that numba's compilation is not counted. Reported per world: the free
area the robot can reach, how the trial ended, simulated and wall time, their ratio (the paper's system
ran in real time: ratio 1), GMapping updates and their mean cost, the share of the wall time spent in
SLAM and in planning, distance and turning. The target of issue 6: a world of about 1,000 m^2 in at most
60 s of wall time on one core.

With several ``--algorithms`` (``gmapping`` runs its ``paper`` preset, any other algorithm its defaults;
the paper's robot and laser either way) the trials are interleaved, seed by seed and world by world,
algorithm after algorithm, so that a slower or busier stretch of a shared machine hits them alike; a
second table then gives each algorithm's wall seconds per simulated second and their ratio to the first
algorithm's, per world and seed and in total.

Default worlds: office_small_01 (small, 153 m^2), mit_building31 and school_medium_01 (about
1,000 m^2; the first from ``../shared/worlds/real``), lab_large_01 (large, 3,092 m^2). Names are
catalog names, real-world folder names under ``$SLAMTRIALS_SHARED/worlds/real``, or map files.

Error profiles (issue 21, item 8): ``--profiles paper realistic --seeds 1 2 3`` (bundled names, or profile
YAML files such as ``slamtrials calibrate`` writes) runs every world with
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


def trial_config(algorithm: str, profile: str = "paper"):
    """The paper's set-up with ``algorithm`` online (GMapping's ``paper`` preset, another's defaults) and the
    simulator's error ``profile``."""
    from slamtrials.campaign.profilefile import is_profile_path, read_profile
    from slamtrials.trial import TrialConfig

    preset = "paper" if algorithm == "gmapping" else None
    chosen = read_profile(profile).model_dump() if is_profile_path(profile) else profile
    return TrialConfig.from_dict({"slam": {"algorithm": algorithm, "preset": preset}, "sim": {"profile": chosen}})


def main() -> None:
    from slamtrials.trial import run_trial
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=list(DEFAULT_WORLDS))
    parser.add_argument("--seeds", "--seed", nargs="+", type=int, default=[1])
    parser.add_argument(
        "--algorithms", nargs="+", default=["gmapping"], help="SLAM algorithms to time, interleaved (first: reference)"
    )
    parser.add_argument(
        "--profiles",
        nargs="+",
        default=["paper"],
        help="simulator error profiles (bundled names or profile YAML files), run interleaved (first: reference)",
    )
    args = parser.parse_args()

    several = len(args.algorithms) > 1 and len(args.profiles) > 1
    configs = {
        (f"{algorithm}/{profile}" if several else algorithm if len(args.algorithms) > 1 else profile): trial_config(
            algorithm, profile
        )
        for algorithm in args.algorithms
        for profile in args.profiles
    }
    for algorithm, config in configs.items():
        started = time.perf_counter()
        run_trial(load_world("house_small_01"), config, 0)  # compiles every kernel
        print(f"warm-up trial of {algorithm} (with compilation): {time.perf_counter() - started:.0f} s", flush=True)
    rows = []
    for seed in args.seeds:
        for name in args.worlds:
            world = load_world(resolve(name))
            for algorithm, config in configs.items():
                load = os.getloadavg()[0]
                cpu = time.process_time()
                record = run_trial(world, config, seed)
                info = dict(record.metadata["trial"])
                info["cpu_time_s"] = time.process_time() - cpu  # this process's CPU time: no waiting for a core
                info["mapped_free"] = mapped_free_fraction(world, record)
                rows.append((world.name, seed, algorithm, info, load))
                digest = hashlib.sha256(record.truth.tobytes() + record.estimate.tobytes()).hexdigest()[:16]
                print(
                    f"{world.name} seed {seed} {algorithm}: {info['termination_reason']} after {info['duration_s']:.0f} s "
                    f"simulated in {info['wall_time_s']:.1f} s (CPU {info['cpu_time_s']:.1f} s), mapped free "
                    f"{info['mapped_free']:.3f}, load {load:.1f}, run digest {digest}",
                    flush=True,
                )

    print(
        f"\n- Machine: {os.cpu_count()} cores, CPU `{cpu_model()}`; one trial at a time, NUMBA_NUM_THREADS=1; "
        f"date {time.strftime('%Y-%m-%d')}; seeds {' '.join(map(str, args.seeds))}; "
        f"algorithms {' '.join(args.algorithms)}; profiles {' '.join(args.profiles)}"
    )
    print()
    print(
        "| world | seed | trial | reachable m^2 | end | mapped | mapped free | simulated s | wall s | CPU s | sim/wall | updates "
        "| SLAM ms per update | SLAM share | planning share | distance m | turning rad | load avg |"
    )
    print("|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, seed, algorithm, info, load in rows:
        wall = info["wall_time_s"]
        print(
            f"| {name} | {seed} | {algorithm} | {info['reachable_area_m2']:,.0f} | {info['termination_reason']} | "
            f"{info['mapped_fraction']:.3f} | {info['mapped_free']:.3f} | "
            f"{info['duration_s']:.0f} | {wall:.1f} | {info['cpu_time_s']:.1f} | {info['realtime_factor']:.1f} | {info['slam_updates']} | "
            f"{1e3 * info['slam_seconds'] / max(info['slam_updates'], 1):.0f} | {info['slam_seconds'] / wall:.0%} | "
            f"{info['explorer']['plan_seconds'] / wall:.0%} | {info['distance_m']:.0f} | {info['turning_rad']:.0f} | {load:.1f} |"
        )
    if len(configs) > 1:
        print_ratios(rows, list(configs))
        print_summary(rows, list(configs))


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


#: The time columns of :func:`print_ratios`: label and seconds of a trial's ``info``. "SLAM wall" is the
#: wall time inside the SLAM algorithm's ``process`` calls, "other wall" the rest of the trial (simulator,
#: explorer, bookkeeping): they tell the cost of the algorithm's own work from that of the simulation.
TIME_COLUMNS = (
    ("wall", lambda info: info["wall_time_s"]),
    ("CPU", lambda info: info["cpu_time_s"]),
    ("SLAM wall", lambda info: info["slam_seconds"]),
    ("other wall", lambda info: info["wall_time_s"] - info["slam_seconds"]),
)


def print_ratios(rows, algorithms: list[str]) -> None:
    """Seconds per simulated second of each algorithm (wall, CPU, and the wall time split into SLAM and the
    rest), and their ratio to the first algorithm's."""
    reference, others = algorithms[0], algorithms[1:]
    per = {(name, seed, algorithm): info for name, seed, algorithm, info, _ in rows}
    cases = list(dict.fromkeys((name, seed) for name, seed, _, _, _ in rows))
    for label, seconds in TIME_COLUMNS:
        header = " | ".join(f"{a} {label} s per sim s" for a in algorithms)
        ratios = " | ".join(f"{a} / {reference}" for a in others)
        print(f"\n| world | seed | {header} | {ratios} |")
        print("|---|---:|" + "---:|" * (len(algorithms) + len(others)))
        totals = {a: [0.0, 0.0] for a in algorithms}
        for name, seed in cases:
            rate = {}
            for algorithm in algorithms:
                info = per[(name, seed, algorithm)]
                rate[algorithm] = seconds(info) / info["duration_s"]
                totals[algorithm][0] += seconds(info)
                totals[algorithm][1] += info["duration_s"]
            cells = " | ".join(f"{rate[a]:.4f}" for a in algorithms)
            ratio_cells = " | ".join(f"{rate[a] / rate[reference]:.2f}" for a in others)
            print(f"| {name} | {seed} | {cells} | {ratio_cells} |")
        rate = {a: spent / simulated for a, (spent, simulated) in totals.items()}
        cells = " | ".join(f"{rate[a]:.4f}" for a in algorithms)
        ratio_cells = " | ".join(f"{rate[a] / rate[reference]:.2f}" for a in others)
        print(f"| all (total {label} / total simulated) | | {cells} | {ratio_cells} |")


def print_summary(rows: list, labels: list[str]) -> None:
    """Per world: mean wall and simulated time of each trial kind, ends, mapped free share, wall-time ratio."""
    print()
    print(
        "| world | trial | trials | ends | mean simulated s | mean wall s | mean mapped free | wall / "
        + labels[0]
        + " |"
    )
    print("|---|---|---:|---|---:|---:|---:|---:|")
    worlds = list(dict.fromkeys(row[0] for row in rows))
    for name in worlds:
        reference = None
        for label in labels:
            mine = [row for row in rows if row[0] == name and row[2] == label]
            wall = sum(row[3]["wall_time_s"] for row in mine) / len(mine)
            sim = sum(row[3]["duration_s"] for row in mine) / len(mine)
            free = sum(row[3]["mapped_free"] for row in mine) / len(mine)
            ends: dict[str, int] = {}
            for row in mine:
                ends[row[3]["termination_reason"]] = ends.get(row[3]["termination_reason"], 0) + 1
            reference = wall if reference is None else reference
            end_text = ", ".join(f"{k} {v}" for k, v in sorted(ends.items()))
            print(
                f"| {name} | {label} | {len(mine)} | {end_text} | {sim:.0f} | {wall:.1f} | {free:.3f} | "
                f"{wall / reference:.2f} |"
            )


if __name__ == "__main__":
    main()
