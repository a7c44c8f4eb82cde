"""Why GMapping's scan matcher costs more per update on noisy data: how far its hill climbing goes.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/studies/gmapping_climb.py [--world office_small_01] [--seed 1]
[--profiles paper realistic] [--sample 10]``.

One trial per error profile (online GMapping with the ``paper`` preset, the paper's robot and laser, as
``bench_trial.py``), after a warm-up trial that compiles every kernel. Every scan-matching update is
watched: the beams it used, its wall time, and how far each particle's hill climbing moved it from the
pose the motion model drew (mean over particles, metres and radians). For every ``--sample``-th update
the climb of each particle is run again through the kernel's Python twin with the score function
counted, giving the score evaluations per particle (the matcher's cost is evaluations x beams). The
counted re-run must return the very poses the compiled matcher returned; the script checks that.
"""

from __future__ import annotations

import os
import sys

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_trial

import argparse  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402

import numpy as np  # noqa: E402

from bench_trial import resolve, trial_config  # noqa: E402


@dataclass
class Watch:
    """Per-update figures of one trial."""

    beams: list[int] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)
    climb_m: list[float] = field(default_factory=list)
    climb_rad: list[float] = field(default_factory=list)
    evaluations: list[float] = field(default_factory=list)  # mean per particle, sampled updates only


def main() -> None:
    import slamtrials.slam.gmapping.filter as gmapping_filter
    import slamtrials.slam.gmapping.kernels as kernels
    from slamtrials.trial.run import run_trial
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="office_small_01")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--profiles", nargs="+", default=["paper", "realistic"])
    parser.add_argument("--sample", type=int, default=10, help="count evaluations on every N-th update")
    args = parser.parse_args()

    for profile in args.profiles:
        run_trial(load_world("house_small_01"), trial_config("gmapping", profile), 0)  # compiles every kernel

    compiled_match = kernels.match_particles
    compiled_score = kernels._match_score
    counter = [0]

    def counted_score(*a):  # noqa: ANN002, ANN202 - the kernel's own arguments
        counter[0] += 1
        return compiled_score(*a)

    def climbs_counted(a) -> tuple[float, np.ndarray]:  # noqa: ANN001 - match_particles' arguments
        """Mean evaluations per particle, and the climbs' end poses, from the Python twin of the climb."""
        directories, mean, col0, row0, res, poses, lx, ly, lfx, lfy = a[:10]
        kernel, sigma, lsigma, free_test, lstep, astep, iterations = a[10:17]
        floats, ints = kernels.score_scratch(lx.shape[0])
        seen = np.empty((kernels._SEEN_CAPACITY, 3))
        kernels._match_score = counted_score  # the Python twin looks its callees up in the module
        try:
            counter[0] = 0
            ends = []
            for p in range(poses.shape[0]):
                x, y, t, _, _ = kernels._hill_climb.py_func(
                    directories[p], mean, col0, row0, res, poses[p], lx, ly, lfx, lfy, kernel, sigma, lsigma,
                    free_test, lstep, astep, iterations, floats, ints, seen,
                )  # fmt: skip
                ends.append((x, y, t))
        finally:
            kernels._match_score = compiled_score
        return counter[0] / poses.shape[0], np.array(ends)

    rows = []
    for profile in args.profiles:
        watch = Watch()

        def watched(*a, watch: Watch = watch):  # noqa: ANN002, ANN202
            started = time.perf_counter()
            out = compiled_match(*a)
            watch.seconds.append(time.perf_counter() - started)
            poses, matched = a[5], out[0]
            watch.beams.append(int(a[6].shape[0]))
            watch.climb_m.append(float(np.mean(np.hypot(*(matched[:, :2] - poses[:, :2]).T))))
            turn = np.angle(np.exp(1j * (matched[:, 2] - poses[:, 2])))
            watch.climb_rad.append(float(np.mean(np.abs(turn))))
            if len(watch.seconds) % args.sample == 1:
                evaluations, ends = climbs_counted(a)
                kept = out[1] > a[17]  # a climb's end is taken when its score beats minimumScore
                same = np.allclose(np.where(kept[:, None], ends[:, :2], poses[:, :2]), matched[:, :2], atol=0.0)
                if not same:
                    raise SystemExit("the counted climb did not end where the compiled matcher did")
                watch.evaluations.append(evaluations)
            return out

        gmapping_filter.match_particles = watched
        try:
            record = run_trial(load_world(resolve(args.world)), trial_config("gmapping", profile), args.seed)
        finally:
            gmapping_filter.match_particles = compiled_match
        rows.append((profile, record.metadata["trial"]["duration_s"], watch))

    print(f"\n{args.world}, seed {args.seed}; GMapping `paper` preset; one row per error profile\n")
    print(
        "| profile | simulated s | updates | beams used | ms per update | score evaluations per particle "
        "(sampled updates) | climb per update, mm | climb per update, mrad |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for profile, duration, w in rows:
        print(
            f"| {profile} | {duration:.0f} | {len(w.seconds)} | {np.mean(w.beams):.0f} | {1e3 * np.mean(w.seconds):.1f} "
            f"| {np.mean(w.evaluations):.1f} ({len(w.evaluations)}) | {1e3 * np.mean(w.climb_m):.1f} "
            f"| {1e3 * np.mean(w.climb_rad):.1f} |"
        )


if __name__ == "__main__":
    main()
