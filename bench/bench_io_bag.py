"""Benchmark of ROS bag export and import: a 30-minute run (18,000 scans x 541 beams at 10 Hz), one core.

Run: ``.venv/bin/python bench/bench_io_bag.py`` (``make bench`` runs all benchmarks). Prints a Markdown
table; the latest figures are kept in bench/RESULTS.md ("ROS bags").

The run is synthetic (no simulation needed): float32 ranges in 0.1..30 m with the structure of a room
(smooth walls plus millimetre noise), a random-walk odometry and ground truth. Each bag carries
18,000 messages on each of /base_scan, /odom, /base_pose_ground_truth, /tf and /stall. Export =
:func:`write_rosbag1` / :func:`write_rosbag2` (message building, serialisation, writing, fsync); import
= :func:`run_from_bag` (decoding /base_scan, /odom and the ground truth, pairing, building the record).
Times are the best of 2 repeats; the process is pinned to one core. Target: each under 10 s.
"""

from __future__ import annotations

import os
import platform
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from benchutil import cpu_model
from slamtrials.io.rosbag import run_from_bag, write_rosbag1, write_rosbag2
from slamtrials.record import LaserGeometry, RunRecord

FRAMES = 18_000  # 30 minutes at 10 Hz
BEAMS = 541  # 270 deg at 0.5 deg, the paper's laser
REPEATS = 2


def synthetic_run(seed: int = 0) -> RunRecord:
    """A 30-minute run of random-walk poses and room-like scans."""
    rng = np.random.default_rng(seed)
    t = np.arange(FRAMES) * 0.1
    steps = np.column_stack([rng.normal(0.03, 0.01, FRAMES), rng.normal(0, 0.002, FRAMES), rng.normal(0, 0.02, FRAMES)])
    truth = np.cumsum(steps, axis=0)
    truth[:, 2] = (truth[:, 2] + np.pi) % (2 * np.pi) - np.pi
    odometry = truth * 1.01
    odometry[:, 2] = (odometry[:, 2] + np.pi) % (2 * np.pi) - np.pi
    angles = np.linspace(-3 * np.pi / 4, 3 * np.pi / 4, BEAMS)
    phase = rng.uniform(0, 2 * np.pi, (FRAMES, 1))
    scans = 4.0 + 3.0 * np.abs(np.sin(angles[None, :] * 2.0 + phase)) + rng.normal(0, 0.001, (FRAMES, BEAMS))
    scans = np.clip(scans, 0.1, 30.0).astype(np.float32)
    laser = LaserGeometry.from_dict(
        {
            "angle_min": float(angles[0]),
            "angle_increment": float(angles[1] - angles[0]),
            "range_min": 0.0,
            "range_max": 30.0,
            "mount": [0.1, 0.0, 0.0],
        }
    )
    return RunRecord(
        t=t,
        scans=scans,
        odometry=odometry,
        truth=truth,
        stalled=rng.random(FRAMES) < 0.01,
        laser=laser,
        metadata={"world": "synthetic", "sim_config": {"dt": 0.1}},
    )


def size_of(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def best_of(repeats: int, action) -> tuple[float, object]:
    best, result = float("inf"), None
    for _ in range(repeats):
        started = time.perf_counter()
        result = action()
        best = min(best, time.perf_counter() - started)
    return best, result


def main() -> None:
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    record = synthetic_run()
    print(f"machine: {os.cpu_count()} cores (pinned to 1), {cpu_model()}; Python {platform.python_version()}")
    print(f"run: {FRAMES:,} scans x {BEAMS} beams ({FRAMES / 10 / 60:.0f} min at 10 Hz)")
    print()
    print("| bag | export (s) | import (s) | size (MB) | export msgs/s | import scans/s |")
    print("|---|---:|---:|---:|---:|---:|")
    folder = Path(tempfile.mkdtemp(prefix="slamtrials-bench-"))
    try:
        for label, writer, name, options in (
            ("ROS 1 (.bag)", write_rosbag1, "run.bag", {}),
            ("ROS 2 (MCAP)", write_rosbag2, "run", {}),
            ("ROS 1, LZ4", write_rosbag1, "lz4.bag", {"compress": True}),
            ("ROS 2, MCAP zstd", write_rosbag2, "zstd", {"compress": True}),
        ):
            path = folder / name
            export_s, _ = best_of(REPEATS, lambda w=writer, p=path, o=options: w(p, record, overwrite=True, **o))
            import_s, back = best_of(REPEATS, lambda p=path: run_from_bag(p))
            assert np.array_equal(back.scans, record.scans) and np.max(np.abs(back.t - record.t)) <= 1e-9
            messages = 5 * FRAMES + 1
            print(
                f"| {label} | {export_s:.2f} | {import_s:.2f} | {size_of(path) / 1e6:.0f} | "
                f"{messages / export_s:,.0f} | {FRAMES / import_s:,.0f} |"
            )
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
