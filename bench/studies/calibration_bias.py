"""How much of a fitted laser profile is the reference's own error: calibrate a replica whose values are known.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/calibration_bias.py LOG PROFILE [KEY=VALUE ...]
[--seed 0] [--bootstrap 10]``.

GMapping (its defaults plus the ``KEY=VALUE`` overrides, seed 0) runs over the real log; its final path and
map make the log's replica, as ``slamtrials validate`` builds it. The replica is recorded once with
``PROFILE`` (a bundled name or a YAML file; seed ``--seed``), so its laser's true values are the profile's.
That recording is then calibrated twice, as ``slamtrials calibrate`` does: against the replica's true path
and world, and against GMapping's own run on the recording (the same settings, seed 0), which is how a real
log is calibrated. Printed: each laser value, true, fitted against the truth and fitted against GMapping.

The gap between the last two columns is what calibrating against a SLAM reference adds to the values: its
pose errors and its map's misplaced walls read as range noise, short readings and edge readings. The gap
between the first two is the fit's own error on this geometry.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402


def log_replica(log: str, overrides: dict):
    """``(record, reference, replica)``: the real log, GMapping's run on it (its defaults plus ``overrides``,
    seed 0) and the replica built from that run, as ``slamtrials validate`` builds it."""
    from slamtrials.external import run_offline
    from slamtrials.slamrun import load_recording
    from slamtrials.validation.validate import replica_from_reference

    record = load_recording(log)
    reference = run_offline(record, "gmapping", overrides=overrides, seed=0)
    return record, reference, replica_from_reference(record, reference)


def record_replica(replica, profile, seed: int):
    """The replica recorded once with ``profile`` (an ErrorProfile), the simulator's stream of run ``seed``."""
    from slamtrials.seeding import run_streams
    from slamtrials.sim.pathreplay import simulate_path
    from slamtrials.validation.validate import replica_config

    rng = np.random.default_rng(run_streams(seed).simulator)
    return simulate_path(replica.world, replica.t, replica.truth, replica_config(replica, profile), rng)


def main() -> None:
    from slamtrials.calibration.fit import calibrate
    from slamtrials.calibration.laser import LASER_VALUES
    from slamtrials.calibration.reference import Reference, slam_reference
    from slamtrials.calibration.settings import CalibrationSettings
    from slamtrials.cli.slam import parse_settings
    from slamtrials.sim.profiles import resolve_profile

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", help="a real log (CARMEN, optionally .bz2/.gz, or a bag)")
    parser.add_argument("profile", help="the replica's profile: a bundled name or a YAML file")
    parser.add_argument("overrides", nargs="*", help="GMapping settings KEY=VALUE (e.g. linearUpdate=0.1)")
    parser.add_argument("--seed", type=int, default=0, help="the replica's seed")
    parser.add_argument("--bootstrap", type=int, default=10, help="bootstrap replicates of each calibration")
    args = parser.parse_args()

    overrides = parse_settings(args.overrides)
    started = time.perf_counter()
    _, _, replica = log_replica(args.log, overrides)
    profile = resolve_profile(args.profile)
    simulated = record_replica(replica, profile, args.seed)
    settings = CalibrationSettings(bootstrap=args.bootstrap)
    against_truth = calibrate(simulated, Reference.from_world(replica.truth, replica.world, "truth"), settings)
    against_slam = calibrate(simulated, slam_reference(simulated, "gmapping", overrides=overrides, seed=0), settings)
    true_values = profile.laser_values()
    print(f"{args.log}, replica recorded with {profile.name} (seed {args.seed}), {time.perf_counter() - started:.0f} s")
    print("| value | true | fitted against the truth | fitted against GMapping |")
    print("|---|---:|---:|---:|")
    for name in LASER_VALUES + ("short_lifetime", "short_fleeting_share"):
        fitted_truth, fitted_slam = against_truth.value(name).value, against_slam.value(name).value
        print(f"| `{name}` | {true_values[name]:.4g} | {fitted_truth:.4g} | {fitted_slam:.4g} |")


if __name__ == "__main__":
    main()
