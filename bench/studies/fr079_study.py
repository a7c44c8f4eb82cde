"""GMapping on fr079: why slam_gmapping's defaults fail there, and which setting matters (issue 20, point 4).

Run: ``SLAMTRIALS_SHARED=<shared> NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/fr079_study.py [--seeds 5]
[--first-seed 0] [--case NAME ...] [--list]`` (all cases, 5 seeds: about 25 minutes on one core). One
core, one run after another (no Dask): each case is a named set of GMapping overrides (slam_gmapping's
defaults otherwise), run with seeds 0..N-1 over ``<shared>/data/fr079`` and scored on ``fr079.relations``
as ``bench_real_logs.py`` scores (mean translational / rotational error over the matched relations).
Prints one Markdown row per case.

Why the cases are these. fr079's odometry loses the sign of the translation: wherever the robot backs up
(``ODOM`` lines with ``tv < 0``: 513 of 8,951 lines, 10.9 m of its 392 m), the logged pose still advances
*forward* along the heading (all 254 steps with ``tv < -0.1 m/s`` do), so the odometry is wrong by twice
the distance reversed, up to 6 m within 6 s (1513.5 to 1519.8 s); the laser and the benchmark's relations
both show the robot going backwards there. On top, the odometry's heading slips where the robot noses
back and forth or turns on the spot (about 40 degrees over 1379-1387 s; 40 to 85 % of the turn per
relation at 2203-2213 s). ``fr079_diagnose.py`` shows that every seed's map goes wrong at those places.
GMapping matches a scan only every ``linearUpdate`` metres / ``angularUpdate`` radians of *odometry*
motion, and its matcher only climbs from where the motion model put the particle, in steps of ``lstep`` /
``astep``, with a score that sees an endpoint only within ``kernelSize`` cells of a mapped one; so the
error that builds up between two updates must stay within that capture range. The cases therefore vary
how much odometry error builds up between matches (the update triggers), the capture range (steps,
particles, motion noise), and, as the control experiment, remove the cause: ``repair`` re-signs the
odometry increments where the ODOM lines report reversing (the data repaired, GMapping's defaults
unchanged). Outcome (bench/RESULTS.md, "fr079: why the defaults fail"): ``linear-0.1`` maps every seed at
0.044 to 0.049 m.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Any

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_real_logs

import numpy as np  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from bench_real_logs import datasets, shared_data  # noqa: E402
from slamtrials.geometry import compose1, ominus1  # noqa: E402
from slamtrials.io.carmen_read import read_carmen  # noqa: E402
from slamtrials.io.relations import read_relations  # noqa: E402
from slamtrials.metric.relerrors import evaluate_relations  # noqa: E402
from slamtrials.record import RunRecord  # noqa: E402
from slamtrials.slam.offline import run_over_recording  # noqa: E402
from slamtrials.slamrun import load_recording  # noqa: E402


@dataclass(frozen=True)
class Case:
    """One row of the study: GMapping overrides, and whether the odometry's reversing is repaired."""

    name: str
    overrides: dict[str, Any] = field(default_factory=dict)
    repair: bool = False
    why: str = ""


CASES = [
    Case("defaults", {}, why="slam_gmapping's defaults: update every 1 m / 0.5 rad of odometry"),
    Case(
        "s10-best",
        {"particles": 100, "srt": 0.4, "stt": 0.4, "lstep": 0.1, "astep": 0.1},
        why="the earlier study's best: more particles, rotational noise and climb steps",
    ),
    Case("repair", {}, repair=True, why="defaults on the odometry with reversing re-signed (control)"),
    Case("temporal-0.5", {"temporalUpdate": 0.5}, why="also match every 0.5 s"),
    Case("linear-0.25", {"linearUpdate": 0.25}, why="match every 0.25 m of odometry"),
    Case("linear-0.2", {"linearUpdate": 0.2}, why="match every 0.2 m of odometry"),
    Case("linear-0.1", {"linearUpdate": 0.1}, why="match every 0.1 m of odometry"),
    Case("every", {"linearUpdate": 0.0}, why="match every reading"),
    Case("repair-linear-0.25", {"linearUpdate": 0.25}, repair=True, why="repaired odometry, every 0.25 m (control)"),
]


def repaired_odometry(record: RunRecord, odom_t: NDArray[np.float64], tv: NDArray[np.float64]) -> RunRecord:
    """``record`` with each reading-to-reading odometry increment's translation negated where the robot
    was backing up (the mean ``tv`` of the ODOM lines in that interval, or of the nearest line, is
    negative); the rotation is kept. float64 poses, composed from the first reading's."""
    odometry = record.odometry
    fixed = np.empty_like(odometry)
    fixed[0] = odometry[0]
    lo = np.searchsorted(odom_t, record.t[:-1], side="right")
    hi = np.searchsorted(odom_t, record.t[1:], side="right")
    nearest = np.clip(np.searchsorted(odom_t, record.t[1:]), 0, len(odom_t) - 1)
    for k in range(1, len(record)):
        a, b = lo[k - 1], hi[k - 1]
        speed = float(np.mean(tv[a:b])) if b > a else float(tv[nearest[k - 1]])
        step = ominus1(odometry[k - 1], odometry[k])
        if speed < 0.0:
            step = np.array([-step[0], -step[1], step[2]])
        fixed[k] = compose1(fixed[k - 1], step)
    return RunRecord(
        t=record.t,
        scans=record.scans,
        odometry=fixed,
        truth=record.truth,
        stalled=record.stalled,
        laser=record.laser,
        metadata=dict(record.metadata),
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5, help="runs per case")
    parser.add_argument("--first-seed", type=int, default=0, help="seeds FIRST .. FIRST + SEEDS - 1")
    parser.add_argument("--case", dest="cases", action="append", default=None, help="case name (default: all)")
    parser.add_argument("--list", action="store_true", help="list the cases and exit")
    args = parser.parse_args()
    if args.list:
        for case in CASES:
            print(f"{case.name}: {case.overrides or 'defaults'}{' + repair' if case.repair else ''} - {case.why}")
        return 0
    chosen = [c for c in CASES if args.cases is None or c.name in args.cases]
    unknown = set(args.cases or []) - {c.name for c in CASES}
    if unknown:
        print(f"unknown case(s) {sorted(unknown)}; --list shows them", file=sys.stderr)
        return 2
    found = datasets(shared_data(), ["fr079"])
    if not found:
        print(f"no fr079 with relations under {shared_data()}; set SLAMTRIALS_SHARED", file=sys.stderr)
        return 2
    _, log, relations_path = found[0]
    record = load_recording(log)
    relations = read_relations(relations_path)
    odom = read_carmen(log, ranges=False).odom
    repaired = repaired_odometry(record, odom.t, odom.tv)
    last = args.first_seed + args.seeds - 1
    print(f"# fr079: GMapping, seeds {args.first_seed}..{last}, one run at a time on one core\n")
    print(
        "| case | settings | eps_t per seed (m) | runs <= 0.10 m | mean eps_t (m) | mean eps_r (rad) | updates | s per run |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for case in chosen:
        eps_t, eps_r, seconds, updates = [], [], [], 0
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            started = time.perf_counter()
            run = run_over_recording(
                repaired if case.repair else record, "gmapping", overrides=case.overrides, seed=seed
            )
            seconds.append(time.perf_counter() - started)
            errors = evaluate_relations(run.trajectory, relations, allow_outside=True)
            eps_t.append(float(np.mean(errors.translational)))
            eps_r.append(float(np.mean(errors.rotational)))
            updates = run.updates
        settings = ", ".join(f"{k} {v}" for k, v in case.overrides.items()) or "defaults"
        if case.repair:
            settings += " (odometry repaired)"
        print(
            f"| {case.name} | {settings} | {', '.join(f'{e:.3f}' for e in eps_t)} "
            f"| {sum(e <= 0.10 for e in eps_t)} of {len(eps_t)} | {np.mean(eps_t):.3f} | {np.mean(eps_r):.3f} "
            f"| {updates} | {np.mean(seconds):.0f} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
