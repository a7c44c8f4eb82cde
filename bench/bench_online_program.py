"""The cost of running SLAM as an online program: GMapping in-process against the same GMapping behind
the ``slamtrials-online/1`` protocol (docs/examples/online_gmapping.py), on the same trials.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_online_program.py [--worlds office_small_01]
[--seeds 1 2 3]``.

For every world and seed, one trial with the built-in ``gmapping`` (``paper`` preset) and one with the
algorithm ``program`` running the reference client with the same preset, interleaved (in-process,
program, next seed ...), after a warm-up of both, in this process. The client rebuilds slamtrials' random
stream, so both trials are the same run bit for bit (checked: the digest of the true and estimated
paths). Reported per trial: frames, wall time of each, their ratio, and the extra time per frame; then
the totals. The extra time holds the client's start (a Python process that imports slamtrials and loads
GMapping's compiled kernels from numba's cache), the JSON lines both ways and the maps GMapping
publishes every 5 s, base64 and parsed.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CLIENT = ROOT / "docs" / "examples" / "online_gmapping.py"


def _config(online: bool):
    from slamtrials.trial import TrialConfig

    if online:
        slam = {"algorithm": "program", "params": {"command": f"{sys.executable} {CLIENT} paper"}}
    else:
        slam = {"algorithm": "gmapping", "preset": "paper"}
    return TrialConfig.from_dict({"slam": slam})


def _digest(record) -> str:
    h = hashlib.sha256()
    for array in (record.truth, record.estimate, record.online):
        h.update(array.tobytes())
    return h.hexdigest()[:12]


def _trial(world, online: bool, seed: int):
    from slamtrials.trial import run_trial

    started = time.perf_counter()
    record = run_trial(world, _config(online), seed)
    return time.perf_counter() - started, record


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=["office_small_01"])
    parser.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    args = parser.parse_args()

    from slamtrials.worlds import load_world

    print(f"CPU: {cpu_model()}; NUMBA_NUM_THREADS={os.environ['NUMBA_NUM_THREADS']}; one process, interleaved")
    warm = load_world("office_small_01")
    for online in (False, True):  # compile / load every kernel once
        _trial(warm, online, 0)
    header = f"{'world':<18} {'seed':>4} {'frames':>6} {'in-process s':>12} {'program s':>9} {'ratio':>6} {'extra ms/frame':>14}  same run"
    print(header)
    totals = [0.0, 0.0, 0]
    for name in args.worlds:
        world = load_world(name)
        for seed in args.seeds:
            inside, a = _trial(world, False, seed)
            outside, b = _trial(world, True, seed)
            same = len(a) == len(b) and _digest(a) == _digest(b)
            extra = 1000.0 * (outside - inside) / len(a)
            print(
                f"{name:<18} {seed:>4} {len(a):>6} {inside:>12.2f} {outside:>9.2f} {outside / inside:>6.3f} "
                f"{extra:>14.2f}  {'yes' if same else 'NO'}",
                flush=True,
            )
            totals[0] += inside
            totals[1] += outside
            totals[2] += len(a)
    inside, outside, frames = totals
    print(
        f"total: {frames} frames, in-process {inside:.1f} s, program {outside:.1f} s, ratio {outside / inside:.3f}, "
        f"extra {1000.0 * (outside - inside) / frames:.2f} ms per frame"
    )


if __name__ == "__main__":
    main()
