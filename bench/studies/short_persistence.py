"""What the large laser residuals of a real log are: short against long, and how long short readings last.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/short_persistence.py LOG --profile NAME [--set KEY=VALUE ...]
[--seed 0] [--lags 1 3 10]``, e.g. ``../shared/data/fr079/fr079.clf.bz2 --profile fr079 --set
linearUpdate=0.1`` or ``../shared/data/mit-csail/mit-csail.clf --profile mit-csail``.

The reference is the calibration's (GMapping's final path and map on the log, ``--set`` its settings).
Every beam that the reference map lets through known free space to a wall (as the calibration keeps
them) gets its residual, reading minus the range cast from the reference pose. A residual beyond 3
sigmas of the profile's range noise (``range_noise_std + range_noise_per_m r``) is short or long.

Printed: the shares of short and long readings by size of the residual (readings through an unmapped
thing can only be short; the reference's misregistration, glass and open doors make both), and, for the
short readings of every 5th scan, the share that has a short reading of the scan ``lag`` frames later
(within 2 m of travel) whose end point lies within 0.15 m of theirs in the map frame: how long what reads
short stays in place, and the lifetime (s) that the decay between the smallest and the largest lag gives
(``short_lifetime``, :mod:`slamtrials.sim.unmapped`). docs/realism.md, "Assumptions", quotes the figures.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402

SIGMAS = 3.0
NEAR_M = 0.15
SIZES_M = ((0.1, 0.2), (0.2, 0.5), (0.5, 1.0), (1.0, 3.0), (3.0, np.inf))


def main() -> None:
    from slamtrials.calibration.reference import slam_reference
    from slamtrials.geometry import compose1
    from slamtrials.sim.profiles import resolve_profile
    from slamtrials.sim.raycast import RaycastMap, cast_scan
    from slamtrials.slamrun import load_recording
    from slamtrials.worlds.world import world_to_map

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("--profile", required=True, help="bundled profile or YAML file: the range noise")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="GMapping setting")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--lags", nargs="+", type=int, default=[1, 3, 10])
    args = parser.parse_args()

    laser_errors = resolve_profile(args.profile).laser_values()
    s0, s1 = laser_errors["range_noise_std"], laser_errors["range_noise_per_m"]
    overrides = {key: yaml.safe_load(value) for key, value in (item.split("=", 1) for item in args.set)}
    record = load_recording(args.log)
    reference = slam_reference(record, "gmapping", overrides=overrides, seed=args.seed)
    walls, known = reference.worlds()
    walls_map, known_map = RaycastMap.for_world(walls), RaycastMap.for_world(known)
    laser = record.laser
    angles = np.ascontiguousarray(laser.beam_angles(record.scans.shape[1]))
    limit = float(laser.range_max)

    def residuals(k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Frame ``k``: residuals ``[K]`` (m) and cast ranges ``[K]`` of its kept beams, end points ``[K, 2]``."""
        pose = compose1(reference.poses[k], laser.mount)
        uv = world_to_map(walls, pose[:2])
        theta = float(pose[2] - walls.origin[2])
        cast = cast_scan(walls_map.dist, uv, theta, angles, limit, walls.resolution)
        through_known = cast_scan(known_map.dist, uv, theta, angles, limit, walls.resolution)
        reading = record.scans[k].astype(np.float64)
        kept = (cast == through_known) & (cast > 0) & (cast < np.float32(limit)) & (reading < limit)
        heading = pose[2] + angles[kept]
        ends = np.c_[pose[0] + reading[kept] * np.cos(heading), pose[1] + reading[kept] * np.sin(heading)]
        return reading[kept] - cast[kept], cast[kept].astype(np.float64), ends

    errors = []
    for k in range(0, len(record), 5):
        e, r, _ = residuals(k)
        errors.append((e, r))
    e = np.concatenate([item[0] for item in errors])
    r = np.concatenate([item[1] for item in errors])
    cut = SIGMAS * (s0 + s1 * r)
    print(f"{args.log}: {e.size} kept beams of every 5th frame; reference {reference.source}")
    print(f"beyond {SIGMAS:g} sigmas: {np.mean(e < -cut):.2%} short, {np.mean(e > cut):.2%} long")
    print("| residual size (m) | short | long |\n|---|---:|---:|")
    for low, high in SIZES_M:
        short = np.mean((e <= -low) & (e > -high) & (e < -cut))
        long = np.mean((e >= low) & (e < high) & (e > cut))
        print(f"| {low:g} to {high:g} | {short:.2%} | {long:.2%} |")

    def short_ends(k: int) -> np.ndarray:
        e, r, ends = residuals(k)
        return ends[e < -SIGMAS * (s0 + s1 * r)]

    print(f"\n| lag (frames) | short readings | share with a short reading of the later scan within {NEAR_M} m |")
    print("|---:|---:|---:|")
    shares = {}
    for lag in args.lags:
        found = total = 0
        for k in range(0, len(record) - lag, 5):
            if np.hypot(*(reference.poses[k + lag, :2] - reference.poses[k, :2])) > 2.0:
                continue
            now, later = short_ends(k), short_ends(k + lag)
            total += len(now)
            if len(now) and len(later):
                found += int(np.count_nonzero(cKDTree(later).query(now, distance_upper_bound=NEAR_M)[0] < NEAR_M))
        shares[lag] = found / max(total, 1)
        print(f"| {lag} | {total} | {shares[lag]:.3f} |")
    first, last = min(shares), max(shares)
    if last > first and 0.0 < shares[last] < shares[first]:
        # what persists decays as exp(-dt / lifetime) between the two lags (the robot moves at most 2 m)
        step = float(np.mean(np.diff(record.t)))
        lifetime = (last - first) * step / float(np.log(shares[first] / shares[last]))
        print(f"\nlifetime of what reads short (lags {first} and {last}, {step:.3f} s per frame): {lifetime:.2f} s")


if __name__ == "__main__":
    main()
