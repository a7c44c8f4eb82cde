"""What measuring a run's cost costs, and how close its memory figure comes: trials with and without the
cost meter (and with tracemalloc, the exact alternative), the meter's time per call, and the SLAM memory
it reads against what the algorithm holds.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_cost.py [--world office_small_01] [--seed 1]
[--repeats 4] [--algorithm gmapping] [--no-tracemalloc]``.

A trial measures its cost with :class:`slamtrials.costmeter.CostMeter`: the thread's CPU clock around
every call into the SLAM algorithm, and the process's resident memory (``/proc/self/status`` ``VmRSS`` and
``VmHWM``, the peak reset through ``/proc/self/clear_refs``) before and after each call. This script runs
the same trial (the paper's set-up, capped at 300 s simulated, as the CI's determinism check) in these
ways, interleaved so that a busier stretch of a shared machine hits them alike:

* ``none``: a meter that measures nothing (the trial as it was before costs were measured);
* ``cpu``: the meter with clocks only (``CostMeter(memory=False)``);
* ``full``: the meter as every trial runs it;
* ``tracemalloc``: no meter, ``tracemalloc`` tracing every allocation (what exact allocation counts cost).

It prints each trial's CPU time (this process's, so waiting for a core does not count), its run digest
(sha256 of the true and estimated paths: the same digest, the same run bit for bit) and the meter's
figures; then the mean CPU time of each way and its ratio to ``none``, and the meter's own time per
measured call, timed alone over 100,000 calls, times the calls of a trial (one per frame), as a share of
the trial's CPU time: the figure that does not depend on the machine's load. Last, one more ``full``
trial whose algorithm is caught as the trial builds it: the bytes it holds at the end (numpy arrays'
``nbytes`` and ``sys.getsizeof`` of everything else it refers to, each object once, as
bench_karto_memory.py counts them) next to the SLAM memory the meter read.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402

from bench_karto_memory import deep_size  # noqa: E402
from benchutil import cpu_model  # noqa: E402


class NullMeter:
    """A meter that measures nothing: the trial without cost measurement."""

    def __init__(self, *, memory: bool = True) -> None:
        pass

    def enter(self) -> None:
        return None

    def leave(self, mark: object, *, update_seconds: float | None = None) -> None:
        pass

    def finish(self, child: object = None, *, in_child: bool = False):
        from slamtrials.cost import RunCost

        return RunCost(None, None, None, None)


def meter_for(mode: str):
    from slamtrials.costmeter import CostMeter

    if mode in ("none", "tracemalloc"):
        return NullMeter
    if mode == "cpu":
        return lambda **_: CostMeter(memory=False)
    return CostMeter


def per_call_us(memory: bool, calls: int = 100_000) -> float:
    """Microseconds of one enter/leave pair of the meter, around nothing."""
    from slamtrials.costmeter import CostMeter

    meter = CostMeter(memory=memory)
    started = time.perf_counter()
    for _ in range(calls):
        meter.leave(meter.enter())
    elapsed = time.perf_counter() - started
    meter.finish()
    return 1e6 * elapsed / calls


def held_at_the_end(trial_run, world, config, seed: int) -> tuple[float, float]:
    """(MiB the algorithm holds at the end of a full trial, the SLAM MiB the meter read in it)."""
    from slamtrials.costmeter import CostMeter

    caught = []
    original = trial_run.get_algorithm

    def catching(name):
        cls = original(name)

        def build(*args, **kwargs):
            caught.append(cls(*args, **kwargs))
            return caught[-1]

        return build

    trial_run.get_algorithm = catching
    trial_run.CostMeter = CostMeter
    try:
        record = trial_run.run_trial(world, config, seed)
    finally:
        trial_run.get_algorithm = original
    return deep_size(caught[-1], set()) / 2**20, record.metadata["cost"]["slam_peak_mib"]


def main() -> None:
    import slamtrials.trial.run as trial_run
    from slamtrials.trial import TrialConfig
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="office_small_01")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--repeats", type=int, default=4)
    parser.add_argument("--algorithm", default="gmapping")
    parser.add_argument("--no-tracemalloc", action="store_true", help="leave out the tracemalloc way")
    args = parser.parse_args()
    modes = ("none", "cpu", "full") + (() if args.no_tracemalloc else ("tracemalloc",))

    preset = "paper" if args.algorithm == "gmapping" else None
    config = TrialConfig.from_dict(
        {
            "sim": {"profile": "paper"},
            "slam": {"algorithm": args.algorithm, "preset": preset},
            "termination": {"max_time": 300.0},
        }
    )
    world = load_world(args.world)
    started = time.perf_counter()
    trial_run.run_trial(load_world("house_small_01"), config, 0)  # compiles or loads every kernel
    print(f"warm-up trial (with any compilation): {time.perf_counter() - started:.0f} s", flush=True)

    cpu: dict[str, list[float]] = {mode: [] for mode in modes}
    slam_mib: list[float] = []
    digests: set[str] = set()
    frames = 0
    for repeat in range(args.repeats):
        for mode in modes if repeat % 2 == 0 else tuple(reversed(modes)):
            trial_run.CostMeter = meter_for(mode)
            if mode == "tracemalloc":
                tracemalloc.start()
            before = time.process_time()
            record = trial_run.run_trial(world, config, args.seed)
            spent = time.process_time() - before
            if mode == "tracemalloc":
                tracemalloc.stop()
            cpu[mode].append(spent)
            frames = len(record)
            digest = hashlib.sha256(record.truth.tobytes() + record.estimate.tobytes()).hexdigest()[:16]
            digests.add(digest)
            cost = record.metadata["cost"]
            if mode == "full":
                slam_mib.append(cost["slam_peak_mib"])
            print(
                f"repeat {repeat} {mode:>11}: CPU {spent:.2f} s, {frames} frames, digest {digest}, "
                f"SLAM CPU {cost['slam_cpu_s']}, SLAM MiB {cost['slam_peak_mib']}, run MiB {cost['run_peak_mib']}",
                flush=True,
            )

    call_us = {"cpu": per_call_us(memory=False), "full": per_call_us(memory=True)}
    held, read = held_at_the_end(trial_run, world, config, args.seed)
    reference = statistics.mean(cpu["none"])
    print(
        f"\n- Machine: {os.cpu_count()} cores, CPU `{cpu_model()}`; NUMBA_NUM_THREADS=1; date {time.strftime('%Y-%m-%d')}; "
        f"{args.world} seed {args.seed}, {args.algorithm}, {args.repeats} repeats per way, interleaved"
    )
    print(
        f"- Runs bit for bit the same in every way: {'yes' if len(digests) == 1 else 'NO: ' + ', '.join(sorted(digests))}"
    )
    print(
        "\n| way | mean CPU s | min CPU s | vs none | meter us per call | calls per trial | meter share of the trial |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|")
    calls = frames + 2
    for mode in modes:
        mean = statistics.mean(cpu[mode])
        per_call = call_us.get(mode)
        share = "" if per_call is None else f"{per_call * calls / 1e6 / reference:.2%}"
        print(
            f"| {mode} | {mean:.2f} | {min(cpu[mode]):.2f} | {mean / reference:.3f} | "
            f"{'' if per_call is None else f'{per_call:.1f}'} | {calls} | {share} |"
        )
    print(
        f"\n- SLAM memory the meter read in the {len(slam_mib)} full trials: "
        f"{', '.join(f'{v:.0f}' for v in slam_mib)} MiB; in one more: {read:.0f} MiB, while the algorithm "
        f"holds {held:.0f} MiB at its end"
    )


if __name__ == "__main__":
    main()
