"""Would a laser fit that undoes the reference's own errors make a log's replicas as hard as the log?

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/debiased_fit.py LOG RELATIONS PROFILE [KEY=VALUE ...]
[--rounds 2] [--runs 3]``.

A laser fit against a SLAM reference holds the reference's errors besides the laser's
(``bench/studies/calibration_bias.py``). This undoes that by indirect inference: find the laser values whose
replica, fitted the same way, gives what the real log gave. GMapping (its defaults plus the ``KEY=VALUE``
overrides, seed 0) runs over the real log; its path and map make the replica, and the laser is fitted
against it (:func:`slamtrials.calibration.beams.beam_sample` and :func:`~slamtrials.calibration.laser.fit_laser`,
no bootstrap, no persistence fit): that is the target. Starting from ``PROFILE``'s laser values, each round
records the replica with the current values (seed = round), runs GMapping on the recording, fits its laser
against that run, and scales each debiased value by target / fitted (a fixed point in log space; the
persistence, the position and range shape of short readings, and the odometry stay the profile's). Printed:
each round's values and fit. Then ``slamtrials validate``'s comparison with the last values, ``--runs``
replicas (seeds 0 to N-1), beside the same with ``PROFILE`` itself.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

#: The laser values scaled each round; the rest are taken from the profile as they are.
DEBIASED = ("range_noise_std", "range_noise_per_m", "short_rate", "edge_chance", "dropout_rate", "dropout_grazing")


def main() -> None:
    from calibration_bias import log_replica, record_replica
    from slamtrials.calibration.beams import beam_sample
    from slamtrials.calibration.laser import fit_laser
    from slamtrials.calibration.reference import Reference, slam_reference
    from slamtrials.calibration.settings import CalibrationSettings
    from slamtrials.cli.slam import parse_settings
    from slamtrials.io.relations import read_relations
    from slamtrials.sim.profiles import resolve_profile
    from slamtrials.validation.validate import ValidationSettings, validate

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", help="a real log (CARMEN, optionally .bz2/.gz, or a bag)")
    parser.add_argument("relations", help="the log's benchmark relations")
    parser.add_argument("profile", help="the starting profile: a bundled name or a YAML file")
    parser.add_argument("overrides", nargs="*", help="GMapping settings KEY=VALUE (e.g. linearUpdate=0.1)")
    parser.add_argument("--rounds", type=int, default=2, help="rounds of the fixed point")
    parser.add_argument("--runs", type=int, default=3, help="replicas of each validation")
    args = parser.parse_args()

    overrides = parse_settings(args.overrides)
    settings = CalibrationSettings()
    started = time.perf_counter()
    record, reference, replica = log_replica(args.log, overrides)
    relations = read_relations(args.relations)

    def laser_fit(recording, against: Reference) -> dict[str, float]:
        sample = beam_sample(recording, against, settings.max_beams, edge_reach=settings.edge_reach)
        fit = fit_laser(sample, settings, recording.laser.range_min)
        assert fit is not None, "too few beams at mapped walls"
        return fit.values

    real_reference = Reference.from_grid(replica.truth, reference.occupancy, "GMapping on the log")
    target = laser_fit(record, real_reference)
    start = resolve_profile(args.profile)
    values = start.laser_values()
    print(f"{args.log}: target (the log's fit) " + ", ".join(f"{k} {target[k]:.4g}" for k in DEBIASED), flush=True)
    for round_ in range(1, args.rounds + 1):
        profile = start.model_copy(update={"laser": {**start.laser, **values}})
        simulated = record_replica(replica, profile, round_)
        fitted = laser_fit(simulated, slam_reference(simulated, "gmapping", overrides=overrides, seed=0))
        for name in DEBIASED:
            if fitted[name] > 0.0 and values[name] > 0.0:
                values[name] *= target[name] / fitted[name]
        print(
            f"round {round_} ({time.perf_counter() - started:.0f} s): fitted "
            + ", ".join(f"{k} {fitted[k]:.4g}" for k in DEBIASED)
            + "; next "
            + ", ".join(f"{k} {values[k]:.4g}" for k in DEBIASED),
            flush=True,
        )
    debiased = start.model_copy(update={"name": f"{start.name}-debiased", "laser": {**start.laser, **values}})
    check = ValidationSettings(overrides=overrides or None, runs=args.runs)
    for profile in (start, debiased):
        result = validate(record, relations, profile, check, reference=reference, replica=replica)
        real = result.real_slam
        t = [r.slam.translational for r in result.replicas]
        r = [r.slam.rotational for r in result.replicas]
        print(
            f"{profile.name}: eps_t {np.mean(t):.4f} against {real.translational:.4f} "
            f"({np.mean(t) / real.translational:.2f}x), eps_r {np.mean(r):.4f} against {real.rotational:.4f} "
            f"({np.mean(r) / real.rotational:.2f}x); per replica " + ", ".join(f"{v:.3f}" for v in t),
            flush=True,
        )


if __name__ == "__main__":
    main()
