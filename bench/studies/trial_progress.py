"""Where a trial's GMapping updates go: how many come before and after most of the map is known.

Run: ``.venv/bin/python bench/studies/trial_progress.py [--world school_medium_01] [--seed 1]``.

Runs one trial with the paper's set-up (:func:`slamtrials.trial.run_trial` defaults) and samples the
free area known to the SLAM map every 5 s of simulated time. Prints, for 80 to 99 % of the final known
free area, when it was first reached (simulated s) and how many of the trial's updates had been done
then. Update counts, not wall time: they do not depend on the machine.
"""

from __future__ import annotations

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/, for bench_trial

from bench_trial import resolve  # noqa: E402
from slamtrials.trial import TrialProgress, run_trial  # noqa: E402
from slamtrials.worlds import load_world  # noqa: E402

FRACTIONS = (0.8, 0.9, 0.95, 0.98, 0.99)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="school_medium_01")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    samples: list[TrialProgress] = []
    record = run_trial(
        load_world(resolve(args.world)), None, args.seed, on_progress=samples.append, progress_period=5.0
    )
    info = record.metadata["trial"]
    final, total = info["mapped_free_area_m2"], info["slam_updates"]
    print(
        f"{args.world} seed {args.seed}: {info['termination_reason']} after {info['duration_s']:.0f} s, "
        f"{total} updates, final known free area {final:.0f} m^2"
    )
    print("| known free area | first at (s) | updates by then | updates after |")
    print("|---:|---:|---:|---:|")
    for fraction in FRACTIONS:
        hit = next((s for s in samples if s.known_free_area >= fraction * final), None)
        if hit is not None:
            print(
                f"| {fraction:.0%} | {hit.t:.0f} | {hit.slam_updates} ({hit.slam_updates / total:.0%}) | "
                f"{total - hit.slam_updates} |"
            )


if __name__ == "__main__":
    main()
