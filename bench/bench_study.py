"""Study orchestration overhead: a study of about 100 runs against the time its runs take divided by the workers.

Run: ``.venv/bin/python bench/bench_study.py [--workers 2] [--sleep 1.0] [--out DIR]``.

The study is 4 cells (``sim.laser.max_range`` 30, 20, 15, 10) of the demo's three buildings with 8 or 9
runs each (``runs.initial 8, max_runs 9``), every run a :class:`slamtrials.campaign.testing.FakeTrial`
that sleeps ``--sleep`` seconds instead of simulating (no CPU needed, so other work on a shared machine
disturbs it little; the run is scored and its folder written as a real one). The local cluster is the
one ``run_study`` starts (``--workers`` single-threaded processes), started here so that Dask's task
stream records when each run started and ended on its worker.

The ideal is the summed run wall times / workers (a run's wall time is measured on its worker, from the
start of the task to its result: the trial, the scoring and the writing of its folder). Reported against
it, what the whole call took (the cluster's start and shutdown included) and where the rest went:

* start: the cluster's start, the checks and the study folder, up to the driver's first event;
* warm-up: from there to the first run starting on each worker (the mean over the workers): a worker
  imports slamtrials when its first task arrives, once;
* gaps: the time each worker sat idle between two runs (the mean over the workers): the driver's and
  the scheduler's own overhead per run (catalog writes, decisions, round trips);
* tail: from the last run's end on its worker to the driver recording it, plus the time the workers
  finished apart (the end of the makespan beyond the ideal);
* end: from the last run recorded to the return, and the cluster's shutdown.

Start, warm-up and end are paid once per call, whatever the runs take; gaps and tail scale with the runs.
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

    from distributed import Client, LocalCluster, get_task_stream

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
    last_run: list[float] = [math.nan]

    def on_event(cell, event) -> None:
        now = time.time()
        if not first:
            first.append(now)
        if event.kind in ("run_done", "run_failed"):
            last_run[0] = now

    load_before = os.getloadavg()[0]
    started = time.time()
    # as slamtrials.campaign.cluster.dask_client starts it
    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(cluster)
    with get_task_stream(client) as stream:
        result = run_study(config, folder, scheduler=client, trial_fn=FakeTrial(sleep=args.sleep), on_event=on_event)
    returned = time.time()
    client.close()
    cluster.close()
    ended = time.time()

    walls = []
    for cell in result.cells:
        with CampaignStore.open(folder / "cells" / cell.name) as store:
            walls += [r.wall_time for r in store.runs() if r.status == "done" and r.wall_time is not None]
    spans: dict[str, list[tuple[float, float]]] = {}
    for task in stream.data:
        for part in task["startstops"]:
            if part["action"] == "compute":
                spans.setdefault(task["worker"], []).append((part["start"], part["stop"]))
    for runs in spans.values():
        runs.sort()
    n = args.workers
    ideal = math.fsum(walls) / n
    total = ended - started
    start = first[0] - started
    warm_up = math.fsum(runs[0][0] - first[0] for runs in spans.values()) / n
    gaps = math.fsum(b[0] - a[1] for runs in spans.values() for a, b in zip(runs, runs[1:])) / n
    end = ended - last_run[0]
    tail = total - ideal - start - warm_up - gaps - end  # the rest of the makespan
    print(f"CPU: {cpu_model()}; load average {load_before:.1f} before, {os.getloadavg()[0]:.1f} after")
    print(f"study: {len(result.cells)} cells x {len(DEMO_WORLDS)} worlds, {len(walls)} runs of {args.sleep:g} s sleep")
    print(f"ideal (run wall times / {n} workers): {ideal:.1f} s")
    print(f"total (cluster start to shutdown): {total:.1f} s; overhead {100 * (total / ideal - 1):.1f} %")
    print(f"  start (cluster, checks, folder): {start:.1f} s")
    print(f"  warm-up (first event to each worker's first run, mean): {warm_up:.1f} s")
    print(
        f"  gaps between runs on a worker (mean over workers): {gaps:.2f} s ({1000 * gaps / (len(walls) / n):.1f} ms a run)"
    )
    print(f"  tail (workers ending apart, last result to the driver): {tail:.1f} s")
    print(
        f"  end (last run recorded to return {returned - last_run[0]:.1f} s, cluster shutdown {ended - returned:.1f} s)"
    )
    once = start + warm_up + end
    print(
        f"paid once per call: {once:.1f} s; per run: {100 * (gaps + tail) / ideal:.1f} % of the ideal "
        f"(the total's overhead for runs of R s each: about {100 * (gaps + tail) / ideal:.1f} % + {once:.0f} s / "
        f"({len(walls)} R / {n}))"
    )
    if args.out is None:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
