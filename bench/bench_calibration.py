"""What the calibration reads back: known values against the truth and against a SLAM reference, the bundled
profiles simulated and re-fitted, and the MIT CSAIL fit with other reference seeds.

Run: ``SLAMTRIALS_SHARED=<shared> .venv/bin/python bench/bench_calibration.py [--part known|roundtrip|seeds]``.
The figures of docs/realism.md, "Calibration", come from here:

``known``
    Tours of ``office_small_01`` (8 goals) and ``school_medium_01`` (8 goals), seed 7, every error model on
    at known values; the fit against the true path and world, and against GMapping's path and map (its
    defaults, seed 0).
``roundtrip``
    The bundled ``mit-csail`` and ``fr079`` profiles simulated on ``school_medium_01`` (seed 3) and fitted
    against the truth.
``seeds``
    MIT CSAIL (shared data) with GMapping seeds 1 and 2 as the reference.

Each fit uses 30 bootstrap replicates (seed 0). Prints every value with its standard error, next to the
true or bundled one.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from slamtrials.calibration import Calibration, CalibrationSettings, Reference, calibrate, slam_reference  # noqa: E402
from slamtrials.sim.config import LaserConfig, OdometryConfig, SimConfig  # noqa: E402
from slamtrials.sim.profiles import BUNDLED_PROFILES  # noqa: E402
from slamtrials.sim.tour import tour_waypoints  # noqa: E402
from slamtrials.sim.waypoints import simulate_waypoints  # noqa: E402
from slamtrials.slamrun import load_recording  # noqa: E402
from slamtrials.worlds import load_world  # noqa: E402

SETTINGS = CalibrationSettings(bootstrap=30)
LASER = {
    "range_noise_std": 0.03,
    "range_noise_per_m": 0.005,
    "short_rate": 0.12,
    "dropout_rate": 0.03,
    "dropout_per_m": 0.0,
    "dropout_grazing": 0.0,
}
#: Random walks per metre and per radian (m/sqrt(m), rad/sqrt(rad), m/sqrt(rad), rad/sqrt(m)) since issue
#: 32; before, 0.05, 0.1, 0.02, 0.02 per 0.1 s step (about these for the tours' 0.05 m, 0.03 rad steps).
ODOMETRY = {
    "bias_linear": -0.02,
    "bias_angular": -0.06,
    "noise_linear_per_m": 0.012,
    "noise_angular_per_rad": 0.02,
    "noise_linear_per_rad": 0.006,
    "noise_angular_per_m": 0.005,
}


def show(title: str, cal: Calibration, compare: dict[str, object]) -> None:
    laser = cal.laser
    print(
        f"{title}: {laser.beams} beams, robust sigma {laser.robust_sigma:.3f} m, off > 0.2 m "
        f"{100 * laser.off_share:.1f} %, no return {100 * laser.no_return_share:.1f} %; "
        f"{cal.odometry.anchors} anchor frames"
    )
    for v in cal.fitted:
        print(f"  {v.name:<22} {v.value:10.5f} +- {v.stderr:8.5f}   {compare.get(v.name, '')}")
    sys.stdout.flush()


def known() -> None:
    truth = {**LASER, **ODOMETRY}
    config = SimConfig(profile="paper", laser=LaserConfig(**LASER), odometry=OdometryConfig(**ODOMETRY))
    for name in ("office_small_01", "school_medium_01"):
        world = load_world(name)
        record = simulate_waypoints(world, tour_waypoints(world, num_goals=8), config, seed=7, max_time=1500)
        print(f"{name}: {len(record)} frames, {record.metadata['outcome']}")
        show(
            f"{name}, truth reference",
            calibrate(record, Reference.from_world(record.truth, world, "truth"), SETTINGS),
            truth,
        )
        started = time.perf_counter()
        reference = slam_reference(record, "gmapping", seed=0)
        print(f"  (GMapping {time.perf_counter() - started:.1f} s)")
        show(f"{name}, GMapping reference", calibrate(record, reference, SETTINGS), truth)


def roundtrip() -> None:
    world = load_world("school_medium_01")
    waypoints = tour_waypoints(world, num_goals=8)
    for name in ("mit-csail", "fr079"):
        record = simulate_waypoints(world, waypoints, SimConfig(profile=name), seed=3, max_time=1500)
        profile = BUNDLED_PROFILES[name]
        drawn = record.metadata.get("bias") or {}
        bundled = {
            **profile.laser,
            **profile.odometry,
            "bias_linear": drawn.get("linear"),
            "bias_angular": drawn.get("angular"),
        }
        print(f"{name} simulated: {len(record)} frames, drawn bias {record.metadata.get('bias')}")
        show(
            f"{name} re-fitted against the truth",
            calibrate(record, Reference.from_world(record.truth, world, "truth"), SETTINGS),
            bundled,
        )


def seeds() -> None:
    shared = Path(os.environ.get("SLAMTRIALS_SHARED", Path(__file__).resolve().parents[1].parent / "shared"))
    log = shared / "data" / "mit-csail" / "mit-csail.clf"
    record = load_recording(log)
    profile = BUNDLED_PROFILES["mit-csail"]
    bundled = {**profile.laser, **profile.odometry}
    for seed in (1, 2):
        show(
            f"mit-csail, GMapping seed {seed}",
            calibrate(record, slam_reference(record, "gmapping", seed=seed), SETTINGS),
            bundled,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=("known", "roundtrip", "seeds"), action="append")
    parts = parser.parse_args().part or ["known", "roundtrip", "seeds"]
    for part in parts:
        {"known": known, "roundtrip": roundtrip, "seeds": seeds}[part]()


if __name__ == "__main__":
    main()
