"""karto's loop closures in one trial: every candidate chain tried, its gates, and what it did to the online error.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/karto_loops.py --world school_medium_01 --seed 3
[--profile paper] [--set loop_match_minimum_response_coarse=0.8 ...] [--all]``.

The trial is the paper's set-up with karto online (its defaults, or ``--set`` overrides). Printed for each
accepted closure (``--all``: every candidate): the node, its time, the candidate chain, the coarse loop
match's response and position variances, the fine response, how far the loop match moved the node's laser
position, and the online position error (the estimate aligned to the truth at the first frame, as the
trial starts them together) in the frame before the node and in the node's frame, after the closure's
optimization. A false closure shows as a jump of metres in both. Then how the trial ended and its error.
"""

from __future__ import annotations

import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_trial

import argparse  # noqa: E402
import math  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402

from bench_trial import resolve  # noqa: E402


def online_errors(online: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """``[T]`` position error (m) of the online estimates ``[T, 3]`` aligned to ``truth`` ``[T, 3]`` at frame 0."""
    from slamtrials.geometry import compose, compose1, inverse

    align = compose1(truth[0], inverse(online[0]))
    placed = compose(np.broadcast_to(align, online.shape), online)
    return np.hypot(placed[:, 0] - truth[:, 0], placed[:, 1] - truth[:, 1])


def main() -> None:
    import slamtrials.trial.run as trial_run
    from slamtrials.campaign.config import MetricSettings
    from slamtrials.campaign.score import score_run
    from slamtrials.trial import TrialConfig
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="school_medium_01")
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--profile", default="paper", help="the simulator's error profile")
    parser.add_argument(
        "--set",
        nargs="+",
        action="extend",
        default=[],
        metavar="KEY=VALUE",
        help="karto parameter overrides (repeatable)",
    )
    parser.add_argument("--all", action="store_true", help="print the rejected candidates too")
    args = parser.parse_args()

    params = {}
    for item in args.set:
        key, _, value = item.partition("=")
        params[key] = yaml.safe_load(value)
    config = TrialConfig.from_dict(
        {"slam": {"algorithm": "karto", "preset": None, "params": params}, "sim": {"profile": args.profile}}
    )
    caught = []
    original = trial_run.get_algorithm

    def catching(name):
        cls = original(name)

        def build(*a, **k):
            caught.append(cls(*a, **k))
            return caught[-1]

        return build

    trial_run.get_algorithm = catching
    record = trial_run.run_trial(load_world(resolve(args.world)), config, args.seed)
    karto = caught[-1]
    errors = online_errors(record.online, record.truth)
    print(f"{args.world} seed {args.seed}, karto {params or 'defaults'}:")
    print(
        "| t (s) | node | chain | coarse response | variance x, y (m^2) | fine response | match moved (m) | online error before -> after (m) |"
    )
    print("|---:|---:|---|---:|---|---:|---:|---|")
    for check in karto.loop_checks:
        if not (check.accepted or args.all):
            continue
        frame = karto.graph.nodes[check.node].frame
        fine = "-" if math.isnan(check.fine_response) else f"{check.fine_response:.3f}"
        verdict = "" if check.accepted else " (rejected)"
        print(
            f"| {record.t[frame]:.1f} | {check.node} | {check.first}..{check.last} | {check.coarse_response:.3f} | "
            f"{check.variance_x:.4f}, {check.variance_y:.4f} | {fine} | {check.jump:.2f}{verdict} | "
            f"{errors[max(frame - 1, 0)]:.2f} -> {errors[frame]:.2f} |"
        )
    info = record.metadata["trial"]
    score = score_run(record, args.seed, MetricSettings())
    print(
        f"\n{info['termination_reason']} after {info['duration_s']:.0f} s simulated, mapped {info['mapped_fraction']:.3f}; "
        f"{karto.loop_closures} closures of {len(karto.loop_checks)} candidates; eps_t {score.eps_t:.3f} m, "
        f"eps_r {score.eps_r:.4f} rad; largest online error {errors.max():.2f} m"
    )


if __name__ == "__main__":
    main()
