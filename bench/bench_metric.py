"""Benchmark of the metric: relations evaluated per second, and the automatic sampling, one core.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_metric.py`` (``make bench`` runs all benchmarks).
Prints a Markdown table; the latest figures are kept in bench/RESULTS.md ("Metric").

Cases:

* ``evaluate``: 1,000,000 relations (random pairs of poses, random order) against a 100,000-pose
  trajectory at 10 Hz with Unix-time stamps (about 1.1e9 s), nearest pose within 0.1 s: matching,
  relative poses and errors (:func:`slamtrials.metric.evaluate_relations`) plus the summary;
* the same with linear interpolation, and with a sparse estimate (every 5th pose) carried to the
  relation timestamps by a 100,000-pose odometry;
* ``sample``: the IROS 2018 sampling on the 100,000-pose trajectory (pilot 500, N from the rule).

Compile time is excluded (one warm-up call first); times are the best of 3 repeats. Target: the first
case under 1 s.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from slamtrials.geometry import compose  # noqa: E402
from slamtrials.metric import draw_pairs, evaluate_relations, relations_between, sample_relations, summarize  # noqa: E402
from slamtrials.record import Trajectory  # noqa: E402

POSES = 100_000
RELATIONS = 1_000_000


def drive(n: int, seed: int = 0) -> tuple[Trajectory, Trajectory]:
    """A 10 Hz random drive (0.05 m steps) and an estimate that drifts from it (a random walk of offsets
    applied in the body frame), stamped from 1.1e9 s."""
    rng = np.random.default_rng(seed)
    steps = np.column_stack([np.full(n, 0.05), np.zeros(n), rng.normal(0.0, 0.05, n)])
    noise = np.column_stack([rng.normal(0.0, 0.002, n), rng.normal(0.0, 0.002, n), rng.normal(0.0, 0.00005, n)])
    truth = np.zeros((n, 3))
    heading = np.cumsum(steps[:, 2])  # 0.05 m forward then a small turn, integrated without a Python loop
    truth[:, 0] = np.cumsum(0.05 * np.cos(heading))
    truth[:, 1] = np.cumsum(0.05 * np.sin(heading))
    truth[:, 2] = np.angle(np.exp(1j * heading))
    estimate = compose(truth, noise.cumsum(axis=0) * 0.1)
    t = 1.1e9 + 0.1 * np.arange(n)
    return Trajectory(t=t, poses=truth), Trajectory(t=t, poses=estimate)


def best_of(repeats: int, fn) -> tuple[float, object]:
    best, result = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def main() -> None:
    truth, estimate = drive(POSES)
    rng = np.random.default_rng(1)
    i, j = draw_pairs(POSES, RELATIONS, rng)
    order = rng.permutation(RELATIONS)
    relations = relations_between(truth, i[order], j[order])
    sparse = Trajectory(t=estimate.t[::5], poses=estimate.poses[::5])
    odometry = estimate

    def full():
        errors = evaluate_relations(estimate, relations)
        return errors, summarize(errors.translational), summarize(errors.rotational)

    cases = [
        ("evaluate, nearest pose", full),
        ("evaluate, interpolated", lambda: evaluate_relations(estimate, relations, interpolate=True)),
        (
            "evaluate, every 5th pose + odometry correction",
            lambda: evaluate_relations(sparse, relations, odometry=odometry),
        ),
        ("sample relations (pilot 500 + N)", lambda: sample_relations(truth, estimate, rng=0)),
    ]
    for _, fn in cases:  # warm-up: compile or load the numba kernels
        fn()
    print(
        f"- Machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}; Python {platform.python_version()}, numpy {np.__version__}"
    )
    print(
        f"- Trajectory: {POSES:,} poses at 10 Hz (t from 1.1e9 s); relations: {RELATIONS:,} random pairs in random order"
    )
    print()
    print("| case | relations | time (s) | relations/s | result |")
    print("|---|---:|---:|---:|---|")
    for name, fn in cases:
        seconds, result = best_of(3, fn)
        if isinstance(result, tuple):
            errors, trans, rot = result
            note = f"eps_t {trans.mean:.3f} +- {trans.std:.3f} m, eps_r {rot.mean:.4f} rad, N={trans.n:,}"
            count = len(errors)
        elif hasattr(result, "count"):
            note = (
                f"s_t {result.std_t:.3f} m, s_r {result.std_r:.4f} rad -> N_t {result.needed_t:,}, N_r {result.needed_r:,}"
                + (" (capped)" if result.capped else "")
            )
            count = result.count + len(result.pilot_relations)
        else:
            note = f"matched {len(result):,}, odometry-corrected {len(result.corrected):,}"
            count = result.n_relations
        print(f"| {name} | {count:,} | {seconds:.3f} | {count / seconds:,.0f} | {note} |")


if __name__ == "__main__":
    main()
