"""Benchmark of the text formats: CARMEN log and TUM trajectory export and import of a 30-minute run.

Run: ``.venv/bin/python bench/bench_io_text.py`` (``make bench`` runs all benchmarks).
Prints a Markdown table; the latest figures are kept in bench/RESULTS.md ("Text formats").

The run: 18,000 frames (30 minutes at 10 Hz) of 541 beams (270 deg, 30 m, the paper's laser), ranges
uniform in [0.1, 30] m, a random-walk trajectory. Export = ``carmen_from_run`` + ``write_carmen`` (one
laser and one ODOM line per frame); import = ``read_carmen`` + ``run_from_carmen``. TUM: ``write_tum`` and
``read_tum`` of the 18,000 ground-truth poses. Times are the best of 3 repeats; target: each CARMEN export
and import under 10 s on one core. Also reads the real MIT CSAIL log if ``../shared`` is present.
"""

from __future__ import annotations

import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from slamtrials.io.carmen import carmen_from_run, read_carmen, run_from_carmen, write_carmen
from slamtrials.io.tum import read_tum, write_tum
from slamtrials.record import LaserGeometry, RunRecord, Trajectory

FRAMES, BEAMS, REPEATS = 18_000, 541, 3
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", Path(__file__).resolve().parents[1].parent / "shared"))


def make_run(seed: int = 0) -> RunRecord:
    rng = np.random.default_rng(seed)
    steps = np.column_stack([rng.normal(0.05, 0.01, FRAMES), rng.normal(0, 0.005, FRAMES), rng.normal(0, 0.02, FRAMES)])
    truth = np.cumsum(steps, axis=0)
    return RunRecord(
        t=np.arange(FRAMES) * 0.1,
        scans=rng.uniform(0.1, 30.0, (FRAMES, BEAMS)).astype(np.float32),
        odometry=truth + rng.normal(0, 0.01, truth.shape),
        truth=truth,
        stalled=np.zeros(FRAMES, dtype=bool),
        laser=LaserGeometry.from_dict(
            {
                "angle_min": -3 * np.pi / 4,
                "angle_increment": 1.5 * np.pi / (BEAMS - 1),
                "range_min": 0.0,
                "range_max": 30.0,
                "mount": [0.0, 0.0, 0.0],
            }
        ),
    )


def best(function, repeats: int = REPEATS) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    record = make_run()
    print(
        f"- Machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}; Python {platform.python_version()}, numpy {np.__version__}"
    )
    print(f"- Run: {FRAMES} frames x {BEAMS} beams; best of {REPEATS}\n")
    print("| format | export (s) | import (s) | file size (MB) |")
    print("|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as folder:
        for kind in ("ROBOTLASER1", "FLASER"):
            path = Path(folder) / f"run-{kind}.clf"
            export = best(lambda p=path, k=kind: write_carmen(p, carmen_from_run(record, kind=k)))
            imported = best(lambda p=path: run_from_carmen(read_carmen(p)))
            print(
                f"| CARMEN {kind} (laser + ODOM lines) | {export:.2f} | {imported:.2f} | {path.stat().st_size / 1e6:.1f} |"
            )
        path = Path(folder) / "truth.tum"
        trajectory = Trajectory(t=record.t, poses=record.truth)
        export = best(lambda: write_tum(path, trajectory))
        imported = best(lambda: read_tum(path))
        print(f"| TUM ({FRAMES} poses) | {export:.3f} | {imported:.3f} | {path.stat().st_size / 1e6:.1f} |")
    real = SHARED / "data" / "mit-csail" / "mit-csail.clf"
    if real.is_file():
        seconds = best(lambda: read_carmen(real))
        log = read_carmen(real)
        print(f"\nread_carmen(mit-csail.clf): {len(log.laser)} scans x {log.laser.beams} beams in {seconds:.2f} s")


if __name__ == "__main__":
    main()
