"""Benchmark of ``karto``: time per node on real logs, and the optimizer's time against graph size.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_karto.py [--quick] [--log PATH ...] [--preset P ...
[--presets-only]]``. Prints
Markdown tables; the latest figures are kept in docs/karto.md ("Speed").

1. Real logs (default: the MIT CSAIL log of ``../shared/data``; ``--log`` adds others, also ``.gz`` or
   ``.bz2``): karto with its defaults over the whole log; wall time per
   frame, per node (matching, linking, loop closing, optimizing; median, 90th percentile, largest),
   loop closures, and every optimizer run's time against the graph's size at that moment.
2. Optimizer scaling: synthetic pose graphs (a robot lapping a rectangle, one node per 0.5 m, each
   node linked to the previous one and to itself one lap earlier), ``N`` = 250 ... 4000 nodes
   (``--quick``: up to 1000), the last lap bent as a loop closure leaves it; time of one
   :func:`~slamtrials.slam.karto.optimize.optimize_pose_graph`.

Compile time is excluded (a warm-up run on the first 200 frames and one optimizer run first). Times are
given as wall time and as this process's CPU time (``time.process_time``, per ``process`` call): on a
shared machine the wall time also counts the waits for a core.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from benchutil import cpu_model
from slamtrials.geometry import compose, ominus  # noqa: E402
from slamtrials.record import Frame, RunRecord  # noqa: E402
from slamtrials.slam import make_algorithm  # noqa: E402
from slamtrials.slam.karto.optimize import information, optimize_pose_graph  # noqa: E402
from slamtrials.slamrun import load_recording  # noqa: E402

SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", Path(__file__).resolve().parents[2] / "shared"))


def frames(record: RunRecord, stop: int | None = None):
    for k in range(len(record) if stop is None else min(stop, len(record))):
        yield Frame(t=float(record.t[k]), ranges=record.scans[k], odometry=record.odometry[k], truth=record.truth[k])


def bench_log(path: Path) -> None:
    record = load_recording(path)
    warm = make_algorithm("karto", record.laser)
    for frame in frames(record, 200):
        warm.process(frame)
    optimize_pose_graph(*lap_graph(300))  # compiles the optimizer, which the first 200 frames may not reach
    karto = make_algorithm("karto", record.laser)
    frame_cpu = np.zeros(len(record))
    node_frames = []
    started, cpu_started = time.perf_counter(), time.process_time()
    for k, frame in enumerate(frames(record)):
        before, cpu = karto.updates, time.process_time()
        karto.process(frame)
        frame_cpu[k] = time.process_time() - cpu
        if karto.updates > before:
            node_frames.append(k)
    total, total_cpu = time.perf_counter() - started, time.process_time() - cpu_started
    node_ms = 1000.0 * np.array([seconds for _, seconds in karto.timings])
    node_cpu_ms = 1000.0 * frame_cpu[node_frames]
    duration = float(record.t[-1] - record.t[0])
    print(f"\n### {path.name}: {len(record)} frames, {duration:.0f} s of log, load average {os.getloadavg()[0]:.1f}\n")
    print(
        "| clock | nodes | loop closures | total (s) | ms per frame | node median (ms) | node p90 (ms) | node max (ms) | "
        "log seconds per second |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for clock, spent, per_node in (
        ("wall (karto's own node timings)", total, node_ms),
        ("CPU", total_cpu, node_cpu_ms),
    ):
        print(
            f"| {clock} | {karto.updates} | {karto.loop_closures} | {spent:.1f} | {1000 * spent / len(record):.2f} | "
            f"{np.median(per_node):.1f} | {np.percentile(per_node, 90):.1f} | {per_node.max():.0f} | {duration / spent:.1f} |"
        )
    if karto.optimizations:
        print("\nOptimizer runs (one per accepted loop closure; wall time):\n")
        print("| nodes | edges | ms | iterations |")
        print("|---|---|---|---|")
        for nodes, edges, seconds, iterations in karto.optimizations:
            print(f"| {nodes} | {edges} | {1000 * seconds:.1f} | {iterations} |")


def lap_graph(n_nodes: int, spacing: float = 0.5, lap: int = 120):
    """A robot lapping a 20 m x 10 m rectangle (``lap`` nodes per lap, ``spacing`` metres apart, each lap
    0.2 m further out): true poses, edges (consecutive nodes, and each node to the node at the same
    place one lap earlier: about two edges per node, as in Karto's graphs of real logs) and a start as
    a loop closure leaves it: the last lap bent by 0.002 rad of heading drift per node."""
    truth = []
    for k in range(n_nodes):
        u = (k % lap) / lap * 60.0
        grow = 0.2 * (k // lap)
        if u < 20.0:
            truth.append((u, -grow, 0.0))
        elif u < 30.0:
            truth.append((20.0 + grow, u - 20.0, math.pi / 2))
        elif u < 50.0:
            truth.append((50.0 - u, 10.0 + grow, -math.pi))
        else:
            truth.append((-grow, 60.0 - u, -math.pi / 2))
    truth = np.array(truth)
    source = list(range(n_nodes - 1)) + list(range(max(n_nodes - lap, 0)))
    target = list(range(1, n_nodes)) + list(range(lap, n_nodes))
    source, target = np.array(source), np.array(target)
    means = ominus(truth[source], truth[target])
    weights = np.repeat(information(np.diag([1e-3, 1e-3, 1e-4]))[None], source.shape[0], axis=0)
    start = truth.copy()
    bent = max(n_nodes - lap, 1)
    steps = ominus(truth[bent - 1 : -1], truth[bent:])
    steps[:, 2] += 0.002
    for k, step in enumerate(steps):
        start[bent + k] = compose(start[bent + k - 1], step)
    return start, source, target, means, weights


def bench_optimizer(sizes: list[int]) -> None:
    print("\n### Optimizer scaling (synthetic laps of a rectangle, the last lap bent as a loop closure leaves it)\n")
    print("| nodes | edges | wall ms | CPU ms | iterations | cost before | cost after |")
    print("|---|---|---|---|---|---|---|")
    optimize_pose_graph(*lap_graph(300))  # compile
    for n in sizes:
        args = lap_graph(n)
        started, cpu = time.perf_counter(), time.process_time()
        result = optimize_pose_graph(*args)
        seconds, cpu = time.perf_counter() - started, time.process_time() - cpu
        print(
            f"| {n} | {args[1].shape[0]} | {1000 * seconds:.1f} | {1000 * cpu:.1f} | {result.iterations} | {result.initial_cost:.3g} | "
            f"{result.final_cost:.3g} |"
        )


def bench_presets(logs: list[Path], presets: list[str]) -> None:
    """karto over each log in each preset: SLAM CPU seconds per log and per node, and the SLAM's own peak
    memory (:class:`~slamtrials.cost.RunCost`: what its calls added to the resident set), next to the
    node count and CPU seconds the C++ original's reference run reports (../shared/data/karto-cpp; another
    machine and session, so a guide, not a ratio)."""
    from slamtrials.slamrun import run_slam

    print("\n### karto per log and preset (SLAM CPU time, after a warm-up run that compiles)\n")
    print(
        "| log | preset | nodes | SLAM CPU s | CPU ms per node | SLAM peak MiB | "
        "C++ reference (guide): nodes, loop CPU s, ms per node |"
    )
    print("|---|---|---:|---:|---:|---:|---|")
    for log in logs:
        record = load_recording(log)
        name = log.name.split(".")[0]
        for preset in presets:
            run_slam(record, "karto", preset=preset, seed=0, source=str(log))  # compiles, warms the caches
            result = run_slam(record, "karto", preset=preset, seed=0, source=str(log))
            cost = result.cost
            cpu = cost.slam_cpu_s if cost is not None and cost.slam_cpu_s is not None else float("nan")
            mib = cost.slam_peak_mib if cost is not None and cost.slam_peak_mib is not None else float("nan")
            guide = "-"
            summary = SHARED / "data" / "karto-cpp" / name / f"{preset}.summary.json"
            if summary.is_file():
                import json

                ref = json.loads(summary.read_text())
                guide = f"{ref['nodes']}, {ref['loop_cpu_s']:.1f}, {1000 * ref['loop_cpu_s'] / ref['nodes']:.1f}"
            print(
                f"| {name} | {preset} | {result.updates} | {cpu:.1f} | {1000 * cpu / max(result.updates, 1):.1f} | "
                f"{mib:.0f} | {guide} |"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller optimizer graphs")
    parser.add_argument("--log", action="append", default=[], help="another CARMEN log (.clf or .clf.bz2)")
    parser.add_argument(
        "--preset",
        action="append",
        default=[],
        help="also run the whole logs in this preset and report SLAM CPU and memory per log (repeatable)",
    )
    parser.add_argument("--presets-only", action="store_true", help="only the per-preset table")
    args = parser.parse_args()
    print(f"CPU: {cpu_model()}; NUMBA_NUM_THREADS={os.environ.get('NUMBA_NUM_THREADS')}")
    logs = [SHARED / "data" / "mit-csail" / "mit-csail.clf"] + [Path(p) for p in args.log]
    if args.preset:
        bench_presets([log for log in logs if log.exists()], args.preset)
        if args.presets_only:
            return
    for log in logs:
        if log.exists():
            bench_log(log)
        else:
            print(f"\n(no {log})")
    bench_optimizer([250, 500, 1000] if args.quick else [250, 500, 1000, 2000, 4000])


if __name__ == "__main__":
    main()
