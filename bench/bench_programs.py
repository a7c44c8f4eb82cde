"""External SLAM programs against the built-in algorithms on the same real log: error and wall time.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_programs.py [--log mit-csail] [--repeats 3]``.

On a log of the Freiburg benchmark (``$SLAMTRIALS_SHARED/data/<log>``), in this process and interleaved
repeat by repeat: the built-in ``gmapping`` (slam_gmapping's defaults), ``karto`` (slam_toolbox's defaults) and
``odometry``, and MRPT's
``icp-slam`` as an offline program (``docs/examples/mrpt/icp_slam.sh`` through
:func:`slamtrials.external.run_program`: the log written as CARMEN, the program run, its trajectory read
back and carried onto the frames). Each is scored with the Freiburg metric on the log's relations (0.1 s
matching). Wall time is that of the algorithm (for the program: its process, writing its input and
reading its output included), after a warm-up of the in-process algorithms; the ratio is to GMapping's
in the same repeat. Needs Debian's ``mrpt-apps``.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", ROOT.parent / "shared"))
ICP = f"sh {ROOT / 'docs' / 'examples' / 'mrpt' / 'icp_slam.sh'} {{input}} {{output}} {{workdir}}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", default="mit-csail")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    from slamtrials.external import run_program
    from slamtrials.io.relations import read_relations
    from slamtrials.metric import evaluate_relations
    from slamtrials.record import Trajectory
    from slamtrials.slam.offline import run_over_recording
    from slamtrials.slam.program import program_spec
    from slamtrials.slamrun import load_recording

    if shutil.which("icp-slam") is None:
        raise SystemExit("MRPT's icp-slam is not installed (apt-get install mrpt-apps)")
    folder = SHARED / "data" / args.log
    log = next(p for p in sorted(folder.iterdir()) if ".clf" in p.name or p.suffix == ".log")
    record = load_recording(log)
    relations = read_relations(folder / f"{args.log}.relations")
    icp = program_spec(command=ICP)

    def score(poses) -> tuple[float, float]:
        errors = evaluate_relations(Trajectory(t=record.t, poses=poses), relations, tolerance=0.1, allow_outside=True)
        return float(errors.translational.mean()), float(errors.rotational.mean())

    def gmapping():
        return run_over_recording(record, "gmapping", seed=0).trajectory.poses

    def karto():
        return run_over_recording(record, "karto", seed=0).trajectory.poses

    def odometry():
        return run_over_recording(record, "odometry", seed=0).trajectory.poses

    def icp_slam():
        return run_program(record, icp, 0).estimate

    runs = {"gmapping": gmapping, "karto": karto, "odometry": odometry, "icp-slam (program)": icp_slam}
    gmapping()  # warm-up: numba's kernels loaded
    karto()
    times: dict[str, list[float]] = {name: [] for name in runs}
    scores: dict[str, tuple[float, float]] = {}
    for _ in range(args.repeats):
        for name, run in runs.items():
            started = time.perf_counter()
            poses = run()
            times[name].append(time.perf_counter() - started)
            scores[name] = score(poses)
    print(f"CPU: {cpu_model()}; {log.name}: {len(record)} scans, {len(relations)} relations; {args.repeats} repeats")
    print(f"{'algorithm':<20} {'eps_t (m)':>10} {'eps_r (rad)':>11} {'median s':>9} {'x gmapping':>10}")
    reference = statistics.median(times["gmapping"])
    for name in runs:
        median = statistics.median(times[name])
        print(
            f"{name:<20} {scores[name][0]:>10.4f} {scores[name][1]:>11.4f} {median:>9.2f} {median / reference:>10.3f}"
        )


if __name__ == "__main__":
    main()
