"""What in an error profile makes GMapping's updates cost more: one fixed tour, one error model changed at a time.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/slam_cost_by_error.py [--worlds office_small_01
school_medium_01] [--goals 6] [--seed 1] [--base realistic]``.

A trial's cost with an error profile mixes two things: the explorer's path (a noisier map can make it
drive longer) and GMapping's cost per update on noisier data. This script holds the path fixed to see
the second alone. Each world gets one waypoint tour (:func:`slamtrials.sim.tour.tour_waypoints`, the
robot driven along it on its true pose, so every variant drives the same path for the same time),
recorded with ``paper``, with ``--base`` and with ``--base`` with one part of its error models turned off
(the others as they are), all from the same seed. GMapping's ``paper`` preset (as a trial runs it) then
runs offline over each recording, one at a time, after a warm-up run. Printed per world and variant:
the updates, GMapping's CPU seconds and milliseconds per update, the ratio of the latter to ``paper``'s,
and the final path's mean position error against the truth (m), so a cheaper variant can be told from
one that simply lost track.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
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
                "name": f"{base}-{label.replace(' ', '-').replace(chr(39), '')}",
                "laser": {**profile.laser, **laser},
                "odometry": {**profile.odometry, **odometry},
            }
        )
        out[f"{base}, {label}"] = SimConfig(profile=changed.model_dump())
    return out


def main() -> None:
    from slamtrials.sim.tour import tour_waypoints
    from slamtrials.sim.waypoints import simulate_waypoints
    from slamtrials.slamrun import run_slam
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=["office_small_01", "school_medium_01"])
    parser.add_argument("--goals", type=int, default=6, help="far goals of each tour")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--base", default="realistic", help="the bundled profile taken apart")
    args = parser.parse_args()

    variants = configs(args.base)
    warm = simulate_waypoints(
        load_world("house_small_01"),
        tour_waypoints(load_world("house_small_01"), num_goals=2),
        variants[args.base],
        seed=0,
        max_time=120,
    )
    run_slam(warm, "gmapping", preset="paper", seed=0)  # compiles every kernel
    print(f"base profile {args.base}; GMapping preset paper; seed {args.seed}; {time.strftime('%Y-%m-%d')}\n")
    print(
        "| world | variant | simulated s | updates | GMapping CPU s | ms per update | / paper | mean position error (m) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in args.worlds:
        world = load_world(name)
        waypoints = tour_waypoints(world, num_goals=args.goals)
        reference = None
        for label, config in variants.items():
            record = simulate_waypoints(world, waypoints, config, seed=args.seed, max_time=3600)
            cpu = time.process_time()
            result = run_slam(record, "gmapping", preset="paper", seed=args.seed)
            cpu = time.process_time() - cpu
            per_update = 1e3 * cpu / max(result.updates, 1)
            reference = per_update if reference is None else reference
            estimate = result.trajectory.poses[:, :2]
            error = float(np.mean(np.hypot(*(estimate - record.truth[:, :2]).T)))
            print(
                f"| {world.name} | {label} | {record.t[-1]:.0f} | {result.updates} | {cpu:.1f} | {per_update:.1f} | "
                f"{per_update / reference:.2f} | {error:.3f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
