"""The exploration quality sweep of issue 6: every real and bundled world, several seeds, paper set-up.

Run: ``.venv/bin/python bench/sweep_trials.py [--seeds 3] [--jobs 2] [--max-area M2] [--out DIR]``.

Each trial runs the paper's robot with online GMapping (``paper`` preset) and the frontier explorer
until the termination rule (:func:`slamtrials.trial.run_trial`). A trial PASSES when it ended by the
rule (``map_converged``) or by running out of frontiers (``no_frontiers``), not by the time cap, and
mapped at least 90 % of the reachable free area of the true world. The target is at least 95 % of
trials passing.

Worlds: the 23 real building maps in ``../shared/worlds/real`` (or ``$SLAMTRIALS_SHARED/worlds/real``)
and the 20 bundled catalog worlds (trials run biggest first); ``--max-area`` skips bigger ones (by the
catalog's or SOURCES' free area, else the loaded world's). Per trial one CSV row goes to ``DIR/trials.csv`` as
soon as it ends (so a long sweep can be watched, resumed with ``--resume`` and its table printed
with ``--report`` before it is done), and the picture of
every failing trial to ``DIR/failures/``. At the end a Markdown table is printed: per world, the
reasons, mapped fractions, simulated and wall times and the simulated-to-wall ratio.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import csv  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor, as_completed  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from benchutil import cpu_model

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", HERE.parent.parent / "shared"))
FIELDS = (
    "world",
    "source",
    "seed",
    "reason",
    "mapped",
    "mapped_connected",
    "observed",
    "reachable_m2",
    "duration_s",
    "wall_s",
    "ratio",
    "updates",
    "slam_s",
    "distance_m",
    "turning_rad",
    "recoveries",
    "blacklisted",
    "passed",
)
PASSING_REASONS = ("map_converged", "no_frontiers")


def world_list(max_area: float | None, names: list[str] | None = None) -> list[tuple[str, str, float]]:
    """``(name or path, source, free area m^2)`` of every world of the sweep, smallest first."""
    from slamtrials.worlds.catalog import catalog_entries

    worlds = [(entry["name"], "catalog", float(entry["free_area_m2"])) for entry in catalog_entries()]
    real = SHARED / "worlds" / "real"
    if real.is_dir():
        areas = {}
        sources = real / "SOURCES.md"
        if sources.is_file():
            for line in sources.read_text(encoding="utf-8").splitlines():
                cells = [c.strip() for c in line.split("|")]
                if len(cells) > 11 and cells[1].startswith("`"):
                    try:
                        areas[cells[1].strip("`")] = float(cells[11].split()[0].replace(",", ""))  # largest region
                    except ValueError:
                        pass
        for folder in sorted(p for p in real.iterdir() if p.is_dir()):
            target = (
                folder / "map.yaml"
                if (folder / "map.yaml").is_file()
                else next(iter(sorted(folder.glob("*.world"))), None)
            )
            if target is not None:
                worlds.append((str(target), "real", areas.get(folder.name, float("nan"))))
    worlds.sort(key=lambda w: (np.nan_to_num(w[2], nan=1e9), w[0]))
    if max_area is not None:
        worlds = [w for w in worlds if not (w[2] > max_area)]
    if names:
        worlds = [w for w in worlds if w[0] in names or (w[1] == "real" and Path(w[0]).parent.name in names)]
    return worlds


def one_trial(world_ref: str, source: str, seed: int, out: str) -> dict:
    """Run one trial in a worker process and return its CSV row."""
    from slamtrials.report.runplot import save_run_figure
    from slamtrials.sim import SimConfig
    from slamtrials.trial import TrialConfig, run_trial
    from slamtrials.worlds import load_world

    world = load_world(world_ref)
    record = run_trial(world, TrialConfig(sim=SimConfig.paper()), seed)  # the paper set-up, named
    info = record.metadata["trial"]
    passed = info["termination_reason"] in PASSING_REASONS and info["mapped_fraction"] >= 0.9
    if not passed:
        folder = Path(out) / "failures"
        folder.mkdir(parents=True, exist_ok=True)
        save_run_figure(
            world,
            record,
            folder / f"{world.name}-{seed}.png",
            title=f"{world.name} seed {seed}: {info['termination_reason']}, mapped {info['mapped_fraction']:.1%}",
        )
    return {
        "world": world.name,
        "source": source,
        "seed": seed,
        "reason": info["termination_reason"],
        "mapped": round(info["mapped_fraction"], 4),
        "mapped_connected": round(info["mapped_fraction_connected"], 4),
        "observed": round(info["observed_fraction"], 4),
        "reachable_m2": round(info["reachable_area_m2"], 1),
        "duration_s": round(info["duration_s"], 1),
        "wall_s": round(info["wall_time_s"], 1),
        "ratio": round(info["realtime_factor"], 1),
        "updates": info["slam_updates"],
        "slam_s": round(info["slam_seconds"], 1),
        "distance_m": round(info["distance_m"], 1),
        "turning_rad": round(info["turning_rad"], 1),
        "recoveries": info["explorer"]["recoveries"],
        "blacklisted": info["explorer"]["goals_blacklisted"],
        "passed": passed,
    }


def table(rows: list[dict]) -> str:
    lines = [
        "| world | m^2 | seeds | passed | end reasons | mapped (min) | simulated s (mean) | updates (mean) | wall s (mean) | sim/wall |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    by_world: dict[str, list[dict]] = {}
    for row in rows:
        by_world.setdefault(row["world"], []).append(row)
    for world, group in sorted(by_world.items(), key=lambda kv: float(kv[1][0]["reachable_m2"])):
        reasons = ", ".join(sorted({r["reason"] for r in group}))
        passed = sum(str(r["passed"]) == "True" for r in group)
        lines.append(
            f"| {world} | {float(group[0]['reachable_m2']):.0f} | {len(group)} | {passed} | {reasons} | "
            f"{min(float(r['mapped']) for r in group):.3f} | {np.mean([float(r['duration_s']) for r in group]):.0f} | "
            f"{np.mean([float(r['updates']) for r in group]):.0f} | {np.mean([float(r['wall_s']) for r in group]):.0f} | "
            f"{np.mean([float(r['ratio']) for r in group]):.1f} |"
        )
    passed = sum(str(r["passed"]) == "True" for r in rows)
    lines.append(f"\n{passed} of {len(rows)} trials passed ({100 * passed / max(len(rows), 1):.1f} %; target 95 %).")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--max-area", type=float, default=None, help="skip worlds with more free area (m^2)")
    parser.add_argument(
        "--worlds", nargs="+", default=None, help="only these worlds (catalog names or real folder names)"
    )
    parser.add_argument("--first-seed", type=int, default=1, help="seeds are first-seed .. first-seed + seeds - 1")
    parser.add_argument("--out", type=Path, default=HERE.parent / "results" / "sweep")
    parser.add_argument("--resume", action="store_true", help="keep the rows already in DIR/trials.csv")
    parser.add_argument(
        "--report", action="store_true", help="only print the table of DIR/trials.csv (e.g. of an unfinished sweep)"
    )
    args = parser.parse_args()
    if args.report:
        with (args.out / "trials.csv").open() as handle:
            print(table(list(csv.DictReader(handle))))
        return
    args.out.mkdir(parents=True, exist_ok=True)
    csv_path = args.out / "trials.csv"
    done: list[dict] = []
    if args.resume and csv_path.is_file():
        with csv_path.open() as handle:
            done = list(csv.DictReader(handle))
    else:
        with csv_path.open("w", newline="") as handle:
            csv.DictWriter(handle, FIELDS).writeheader()
    finished = {(r["world"], int(r["seed"])) for r in done}
    jobs = [
        (ref, source, seed)
        for ref, source, _ in world_list(args.max_area, args.worlds)
        for seed in range(args.first_seed, args.first_seed + args.seeds)
        if ((Path(ref).parent.name if source == "real" else ref), seed) not in finished
    ]
    jobs.reverse()  # the biggest worlds first, so that no worker is left alone with a long trial at the end
    print(f"CPU: {cpu_model()}; {len(jobs)} trials to run ({len(finished)} done), {args.jobs} at a time", flush=True)
    started = time.perf_counter()
    rows = list(done)
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        futures = {}
        for ref, source, seed in jobs:
            futures[pool.submit(one_trial, ref, source, seed, str(args.out))] = (ref, seed)
        for future in as_completed(futures):
            ref, seed = futures[future]
            try:
                row = future.result()
            except Exception as exc:  # a crashing trial is a failure to report, not a reason to stop the sweep
                row = {
                    "world": Path(ref).parent.name if "/" in ref else ref,
                    "source": "?",
                    "seed": seed,
                    "reason": f"error: {type(exc).__name__}: {exc}"[:200],
                    "mapped": 0,
                    "mapped_connected": 0,
                    "observed": 0,
                    "reachable_m2": 0,
                    "duration_s": 0,
                    "wall_s": 0,
                    "ratio": 0,
                    "updates": 0,
                    "slam_s": 0,
                    "distance_m": 0,
                    "turning_rad": 0,
                    "recoveries": 0,
                    "blacklisted": 0,
                    "passed": False,
                }
            rows.append(row)
            with csv_path.open("a", newline="") as handle:
                csv.DictWriter(handle, FIELDS).writerow(row)
            print(
                f"{row['world']} seed {seed}: {row['reason']}, mapped {float(row['mapped']):.3f}, "
                f"{float(row['duration_s']):.0f} s in {float(row['wall_s']):.0f} s, {row['updates']} updates, "
                f"{float(row['distance_m']):.0f} m, {float(row['turning_rad']):.0f} rad",
                flush=True,
            )
    print(f"\nSweep wall time: {time.perf_counter() - started:.0f} s\n")
    print(table(rows))


if __name__ == "__main__":
    main()
