"""Study orchestration overhead: a study of about 100 runs against the time its runs take divided by the workers.

Run: ``.venv/bin/python bench/bench_study.py [--workers 2] [--sleep 1.0] [--out DIR]``.

The study is 4 cells (``sim.laser.max_range`` 30, 20, 15, 10) of the demo's three buildings with 8 or 9
runs each (``runs.initial 8, max_runs 9``), every run a :class:`slamtrials.campaign.testing.FakeTrial`
that sleeps ``--sleep`` seconds instead of simulating (no CPU needed, so other work on a shared machine
does not disturb it; the run is scored and its folder written as a real one). ``run_study`` starts a
local cluster of ``--workers`` processes and drives every cell on it at once. Reported: runs, the ideal
wall time (summed run wall times / workers), the measured wall time from the first event (after the
cluster started) to the end, the overhead over the ideal in per cent, and the cluster's start-up apart.
Issue 35's target: under 5 % over the ideal.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import shutil  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--sleep", type=float, default=1.0, help="seconds each fake run sleeps")
    parser.add_argument("--out", type=Path, default=None, help="study folder (default: a temporary one)")
    args = parser.parse_args()

    from slamtrials.campaign import DEMO_WORLDS
    from slamtrials.campaign.store import CampaignStore
    from slamtrials.campaign.testing import FakeTrial
    from slamtrials.study import run_study

    root = Path(tempfile.mkdtemp(prefix="bench-study-")) if args.out is None else args.out
    folder = root / "study"
    config = {
        "campaign": {"worlds": list(DEMO_WORLDS), "seed": 0, "runs": {"initial": 8, "max_runs": 9}},
        "axes": {"sim.laser.max_range": [30, 20, 15, 10]},
    }
    first: list[float] = []

    def on_event(cell, event) -> None:
        if not first:
            first.append(time.perf_counter())

    started = time.perf_counter()
    result = run_study(config, folder, workers=args.workers, trial_fn=FakeTrial(sleep=args.sleep), on_event=on_event)
    ended = time.perf_counter()
    walls = []
    for cell in result.cells:
        with CampaignStore.open(folder / "cells" / cell.name) as store:
            walls += [r.wall_time for r in store.runs() if r.status == "done" and r.wall_time is not None]
    ideal = math.fsum(walls) / args.workers
    measured = ended - first[0]
    print(f"CPU: {cpu_model()}; load average {os.getloadavg()[0]:.1f}")
    print(f"study: {len(result.cells)} cells x {len(DEMO_WORLDS)} worlds, {len(walls)} runs of {args.sleep:g} s sleep")
    print(f"ideal (run wall times / {args.workers} workers): {ideal:.1f} s")
    print(f"measured (first event to end): {measured:.1f} s; overhead {100 * (measured / ideal - 1):.1f} %")
    print(f"cluster start and checks before the first event: {first[0] - started:.1f} s")
    if args.out is None:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
