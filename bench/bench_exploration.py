"""What the exploration measures cost a trial: the coverage curve's map samples and the measures at the end.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_exploration.py [--worlds NAME ...] [--seeds 1 ...]
[--algorithm gmapping]``.

A trial records, at most once a simulated second and only when SLAM published a new map, when each map
cell was first known (:class:`slamtrials.trial.firstknown.FirstKnown`), and at the end reads that raster
at the reachable world cells to draw the coverage curve (:mod:`slamtrials.trial.exploration`). This
script times both on the thread's CPU clock inside real trials (the paper's set-up, each world after a
warm-up trial that compiles the kernels) and prints, per trial: the samples taken, the CPU time of the
samples and of the measures at the end, their share of the trial's CPU time, the map's size at the end,
the measures themselves, and the run digest (sha256 of the true and estimated paths: the same digest as
without the measures, the same run bit for bit).
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import functools  # noqa: E402
import hashlib  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402

HERE = Path(__file__).resolve().parent
DEFAULT_WORLDS = ("office_small_01", "school_medium_01", "lab_large_01")


class Timed:
    """Wraps a function, summing the thread CPU time of its calls."""

    def __init__(self, function):  # noqa: ANN001 - any callable
        self.function = function
        self.seconds = 0.0
        self.calls = 0

    def __call__(self, *args, **kwargs):  # noqa: ANN002, ANN003
        started = time.thread_time()
        try:
            return self.function(*args, **kwargs)
        finally:
            self.seconds += time.thread_time() - started
            self.calls += 1

    def __get__(self, instance, owner=None):  # noqa: ANN001 - a method: bind it to the instance
        return self if instance is None else functools.partial(self, instance)


def main() -> None:
    import slamtrials.trial.run as trial_run
    from slamtrials.trial import TrialConfig
    from slamtrials.trial.exploration import ExplorationMeasures
    from slamtrials.trial.firstknown import FirstKnown
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=list(DEFAULT_WORLDS))
    parser.add_argument("--seeds", nargs="+", type=int, default=[1])
    parser.add_argument("--algorithm", default="gmapping")
    args = parser.parse_args()

    preset = "paper" if args.algorithm == "gmapping" else None
    config = TrialConfig.from_dict(
        {"slam": {"algorithm": args.algorithm, "preset": preset}, "sim": {"profile": "paper"}}
    )
    trial_run.run_trial(load_world("house_small_01"), config, 0)  # compiles every kernel

    update, measure = Timed(FirstKnown.update), Timed(trial_run._exploration)
    FirstKnown.update = update  # type: ignore[method-assign]
    trial_run._exploration = measure
    rows = []
    for seed in args.seeds:
        for name in args.worlds:
            world = load_world(name)
            update.seconds = measure.seconds = 0.0
            update.calls = measure.calls = 0
            started = time.thread_time()
            record = trial_run.run_trial(world, config, seed)
            cpu = time.thread_time() - started
            found = ExplorationMeasures.of(record.metadata)
            assert found is not None
            digest = hashlib.sha256(record.truth.tobytes() + record.estimate.tobytes()).hexdigest()[:16]
            info = record.metadata["trial"]
            rows.append(
                (name, seed, info, cpu, update.calls, update.seconds, measure.seconds, record.map.grid.shape, found)
            )
            print(
                f"{name} seed {seed}: {info['termination_reason']} after {info['duration_s']:.0f} s simulated, CPU "
                f"{cpu:.1f} s, {update.calls} samples in {update.seconds * 1e3:.0f} ms, measures {measure.seconds * 1e3:.0f} ms "
                f"({(update.seconds + measure.seconds) / cpu:.2%}), run digest {digest}",
                flush=True,
            )

    print(
        f"\n- Machine: {os.cpu_count()} cores, CPU `{cpu_model()}`; NUMBA_NUM_THREADS=1; {args.algorithm}, paper "
        f"profile; date {time.strftime('%Y-%m-%d')}"
    )
    print()
    print(
        "| world | seed | reachable m^2 | end | simulated s | trial CPU s | samples | map cells | ms per sample "
        "| measures at the end ms | share of the trial | final coverage | time to 90 % s | distance to 90 % m "
        "| time to 99 % s | distance to 99 % m |"
    )
    print("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    fmt = lambda v, spec: "-" if v is None else format(v, spec)  # noqa: E731
    for name, seed, info, cpu, calls, sampling, measuring, shape, found in rows:
        print(
            f"| {name} | {seed} | {info['reachable_area_m2']:,.0f} | {info['termination_reason']} | "
            f"{info['duration_s']:.0f} | {cpu:.1f} | {calls} | {shape[0] * shape[1]:,} | "
            f"{sampling * 1e3 / max(calls, 1):.2f} | {measuring * 1e3:.0f} | {(sampling + measuring) / cpu:.2%} | "
            f"{found.final_coverage:.3f} | {fmt(found.time_to_90_s, '.0f')} | {fmt(found.distance_to_90_m, '.0f')} | "
            f"{fmt(found.time_to_99_s, '.0f')} | {fmt(found.distance_to_99_m, '.0f')} |"
        )


if __name__ == "__main__":
    main()
