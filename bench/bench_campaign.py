"""Campaign throughput: runs per hour of the demo campaign on 2 workers, and the speed-up from 1 to 2.

Run: ``.venv/bin/python bench/bench_campaign.py [--workers 1 2] [--initial 5] [--max-runs 10] [--out DIR]``.

The campaign is :func:`slamtrials.campaign.small_campaign_config` (the README's main job: three small
bundled worlds, the paper's robot with online GMapping, ``initial`` runs then the Section III-C rule, a
low cap), run from scratch in a fresh folder once per worker count on a local Dask cluster
(``run_campaign(..., workers=N)``). The same seed gives the same runs whatever the worker count, which
the script checks, so the wall times compare the same work. Reported per worker count: runs, wall time
(including the cluster's start), runs per hour, the summed run time (CPU-seconds of the runs, as the
workers measured them) and the parallel efficiency; then the speed-up (wall time of 1 worker / wall
time of N). The target is a speed-up of at least 1.8 from 1 to 2 workers. The machine's load average
is printed too, since other work on a shared machine slows the runs down.

``--fake-sleep S`` measures the orchestration alone: the same campaign with
:class:`slamtrials.campaign.testing.FakeTrial` runs that sleep ``S`` seconds instead of simulating (no
CPU needed, so other work on the machine does not disturb it); the speed-up then shows what the Dask
driver, the catalog and the run folders cost.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402


def run_once(
    workers: int, folder: Path, initial: int, max_runs: int, seed: int, fake_sleep: float | None = None
) -> dict:
    """One campaign from scratch with ``workers`` local worker processes."""
    from slamtrials.campaign import run_campaign, small_campaign_config
    from slamtrials.campaign.store import CampaignStore
    from slamtrials.campaign.testing import FakeTrial

    config = small_campaign_config(seed=seed, initial=initial, max_runs=max_runs)
    trial_fn = None if fake_sleep is None else FakeTrial(sleep=fake_sleep)
    load_before = os.getloadavg()[0]
    ready: list[float] = []

    def on_event(event) -> None:
        if not ready:
            ready.append(time.perf_counter())

    cpu_before = resource.getrusage(resource.RUSAGE_SELF)
    started = time.perf_counter()
    result = run_campaign(config, folder, workers=workers, trial_fn=trial_fn, on_event=on_event)
    wall = time.perf_counter() - started
    cpu_after = resource.getrusage(resource.RUSAGE_SELF)
    driver_cpu = (cpu_after.ru_utime - cpu_before.ru_utime) + (cpu_after.ru_stime - cpu_before.ru_stime)
    with CampaignStore.open(folder) as store:
        run_seconds = sum(r.wall_time or 0.0 for r in store.runs())
    return {
        "workers": workers,
        "runs": result.runs_done,
        "wall": wall,
        "startup": ready[0] - started,
        "runs_per_hour": 3600.0 * result.runs_done / wall,
        "run_seconds": run_seconds,
        "efficiency": run_seconds / (wall * workers),
        "driver_cpu": driver_cpu,
        "load": (load_before, os.getloadavg()[0]),
        "summary": [(r.world, r.status, r.runs, r.eps_t.mean, r.eps_r.mean) for r in result.summary],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--workers", type=int, nargs="+", default=[1, 2], help="worker counts to compare (first is the baseline)"
    )
    parser.add_argument("--initial", type=int, default=5, help="first batch of runs per world")
    parser.add_argument("--max-runs", type=int, default=10, help="cap on the runs per world")
    parser.add_argument("--seed", type=int, default=0, help="root seed")
    parser.add_argument(
        "--fake-sleep",
        type=float,
        default=None,
        help="runs that sleep this long instead of simulating (orchestration only)",
    )
    parser.add_argument(
        "--out", type=Path, default=None, help="keep the campaign folders here (default: a temporary folder)"
    )
    args = parser.parse_args()

    base = args.out or Path(tempfile.mkdtemp(prefix="bench_campaign_"))
    rows = []
    try:
        for workers in args.workers:
            folder = base / f"workers-{workers}"
            if folder.exists():
                shutil.rmtree(folder)
            rows.append(run_once(workers, folder, args.initial, args.max_runs, args.seed, args.fake_sleep))
            r = rows[-1]
            print(f"{workers} worker(s): {r['runs']} runs in {r['wall']:.0f} s", flush=True)
    finally:
        if args.out is None:
            shutil.rmtree(base, ignore_errors=True)

    same = all(r["summary"] == rows[0]["summary"] for r in rows)
    print()
    print(f"- Machine: {os.cpu_count()} cores, CPU `{cpu_model()}`; date {time.strftime('%Y-%m-%d')}")
    fake = "" if args.fake_sleep is None else f" with FakeTrial(sleep={args.fake_sleep}) runs (orchestration only)"
    print(
        f"- Campaign: small_campaign_config(seed={args.seed}, initial={args.initial}, max_runs={args.max_runs}){fake}; "
        f"worlds {', '.join(w for w, *_ in rows[0]['summary'])}"
    )
    print(f"- Same runs and errors for every worker count: {'yes' if same else 'NO'}")
    print()
    print(
        "| workers | runs | wall time (s) | cluster start (s) | runs per hour | run time summed (s) | efficiency | speed-up | "
        "speed-up after start | driver + scheduler CPU (s) | load avg before/after |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        speedup = rows[0]["wall"] / r["wall"]
        after = (rows[0]["wall"] - rows[0]["startup"]) / (r["wall"] - r["startup"])
        print(
            f"| {r['workers']} | {r['runs']} | {r['wall']:.0f} | {r['startup']:.1f} | {r['runs_per_hour']:.0f} | {r['run_seconds']:.0f} | "
            f"{100 * r['efficiency']:.0f} % | {speedup:.2f}x | {after:.2f}x | {r['driver_cpu']:.1f} | "
            f"{r['load'][0]:.1f} / {r['load'][1]:.1f} |"
        )
    print()
    print("| world | status | runs | eps_t mean (m) | eps_r mean (rad) |")
    print("|---|---|---:|---:|---:|")
    for world, status, runs, eps_t, eps_r in rows[-1]["summary"]:
        print(f"| {world} | {status} | {runs} | {eps_t:.4f} | {eps_r:.5f} |")


if __name__ == "__main__":
    main()
