"""What in an error profile makes GMapping's updates cost more: one fixed tour, one error model changed at a time.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/slam_cost_by_error.py [--worlds office_small_01
school_medium_01] [--seed 1] [--base realistic]``.

A trial's cost with an error profile mixes two things: the explorer's path (a noisier map can make it
drive longer) and GMapping's cost per update on noisier data. This script holds the path fixed to see
the second alone. Each world gets one trial with the ``paper`` profile (GMapping's ``paper`` preset, the
frontier explorer, ``--seed``); its true path is then sensed again at its own timestamps
(:func:`slamtrials.sim.pathreplay.simulate_path`, so every variant drives the same path for the same
time) with ``paper``, with ``--base`` and with ``--base`` with one part of its error models turned off
(the others as they are), all from the same seed. GMapping's ``paper`` preset (as a trial runs it) then
runs offline over each recording, one at a time, after a warm-up run. Printed per world and variant:
the updates, GMapping's CPU seconds and milliseconds per update, the ratio of the latter to ``paper``'s,
and the final path's mean position error against the truth (m, the path's first pose put on the
truth's), so a cheaper variant can be told from one that simply lost track.
"""

from __future__ import annotations

import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_trial

import argparse  # noqa: E402
import re  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

#: The parts of a profile turned off one at a time: label -> laser and odometry fields set to these values.
VARIANTS: dict[str, tuple[dict[str, float], dict[str, object]]] = {
    "no short readings": ({"short_rate": 0.0}, {}),
    "no edge readings": ({"edge_chance": 0.0}, {}),
    "no range noise": ({"range_noise_std": 0.0, "range_noise_per_m": 0.0}, {}),
    "no dropouts": ({"dropout_rate": 0.0, "dropout_per_m": 0.0, "dropout_grazing": 0.0}, {}),
    "no odometry noise": (
        {},
        {
            "noise_linear_per_m": 0.0,
            "noise_angular_per_rad": 0.0,
            "noise_linear_per_rad": 0.0,
            "noise_angular_per_m": 0.0,
        },
    ),
    "paper's odometry biases": (
        {},
        {"bias_linear_range": (-0.005, 0.005), "bias_angular_range": (-0.017453, 0.017453)},
    ),
    "paper's laser (its odometry only)": (
        {"range_noise_std": 0.0, "range_noise_per_m": 0.0, "short_rate": 0.0, "edge_chance": 0.0}
        | {"dropout_rate": 0.0, "dropout_per_m": 0.0, "dropout_grazing": 0.0},
        {},
    ),
    "paper's odometry (its laser only)": (
        {},
        {
            "noise_linear_per_m": 0.0,
            "noise_angular_per_rad": 0.0,
            "noise_linear_per_rad": 0.0,
            "noise_angular_per_m": 0.0,
        }
        | {"bias_linear_range": (-0.005, 0.005), "bias_angular_range": (-0.017453, 0.017453)},
    ),
}


def configs(base: str) -> dict[str, object]:
    """label -> SimConfig: ``paper``, ``base`` and ``base`` with each of :data:`VARIANTS` applied."""
    from slamtrials.sim.config import SimConfig
    from slamtrials.sim.profiles import resolve_profile

    profile = resolve_profile(base)
    out = {"paper": SimConfig(profile="paper"), base: SimConfig(profile=base)}
    for label, (laser, odometry) in VARIANTS.items():
        changed = profile.model_copy(
            update={
                "name": f"{base}-" + re.sub(r"[^A-Za-z0-9]+", "-", label).strip("-"),
                "laser": {**profile.laser, **laser},
                "odometry": {**profile.odometry, **odometry},
            }
        )
        out[f"{base}, {label}"] = SimConfig(profile=changed.model_dump())
    return out


def mean_position_error(estimate: np.ndarray, truth: np.ndarray) -> float:
    """Mean distance (m) between the poses ``estimate`` ``[N, 3]`` (SLAM's map frame) and ``truth`` ``[N, 3]``
    (world frame), the estimate carried into the world frame by the transform that puts its first pose on
    the truth's first."""
    turn = truth[0, 2] - estimate[0, 2]
    c, s = np.cos(turn), np.sin(turn)
    d = estimate[:, :2] - estimate[0, :2]
    x = truth[0, 0] + c * d[:, 0] - s * d[:, 1]
    y = truth[0, 1] + s * d[:, 0] + c * d[:, 1]
    return float(np.mean(np.hypot(x - truth[:, 0], y - truth[:, 1])))


def main() -> None:
    from bench_trial import trial_config
    from slamtrials.sim.pathreplay import simulate_path
    from slamtrials.slamrun import run_slam
    from slamtrials.trial import run_trial
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=["office_small_01", "school_medium_01"])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--base", default="realistic", help="the bundled profile taken apart")
    args = parser.parse_args()

    variants = configs(args.base)
    warm = run_trial(load_world("house_small_01"), trial_config("gmapping", args.base), 0)  # compiles every kernel
    run_slam(warm, "gmapping", preset="paper", seed=0)
    print(f"base profile {args.base}; GMapping preset paper; seed {args.seed}; {time.strftime('%Y-%m-%d')}\n")
    print(
        "| world | variant | simulated s | updates | GMapping CPU s | ms per update | / paper | mean position error (m) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in args.worlds:
        world = load_world(name)
        path = run_trial(world, trial_config("gmapping", "paper"), args.seed)
        reference = None
        for label, config in variants.items():
            record = simulate_path(world, path.t, path.truth, config, args.seed)
            cpu = time.process_time()
            result = run_slam(record, "gmapping", preset="paper", seed=args.seed)
            cpu = time.process_time() - cpu
            per_update = 1e3 * cpu / max(result.updates, 1)
            reference = per_update if reference is None else reference
            error = mean_position_error(result.trajectory.poses, record.truth)
            print(
                f"| {world.name} | {label} | {record.t[-1]:.0f} | {result.updates} | {cpu:.1f} | {per_update:.1f} | "
                f"{per_update / reference:.2f} | {error:.3f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
