"""The cost of running SLAM as an online program: GMapping in-process against the same GMapping behind
the ``slamtrials-online/1`` protocol (docs/examples/online_gmapping.py), on the same trials.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_online_program.py [--worlds office_small_01]
[--seeds 1 2 3]``.

For every world and seed, one trial with the built-in ``gmapping`` (``paper`` preset) and one with the
algorithm ``program`` running the reference client with the same preset, interleaved (in-process,
program, next seed ...), after a warm-up of both, in this process. The client rebuilds slamtrials' random
stream, so both trials are the same run bit for bit (checked: the digest of the true and estimated
paths). Reported per trial: frames; the whole trial's wall time each way and their ratio (what a campaign
pays); the SLAM seconds in-process, the client's own GMapping seconds (it writes them to
``$ONLINE_GMAPPING_SECONDS``), and the protocol's cost per frame: the adapter's SLAM seconds less the
client's, i.e. the JSON lines both ways, the maps GMapping publishes every 5 s (base64, parsed), and the
client's start (a Python process importing slamtrials). The client's GMapping is slower than the
in-process one by the loading of numba's cached kernels in a fresh process, once per trial.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

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


def _trial(world, online: bool, seed: int, timing: Path):
    from slamtrials.trial import run_trial

    timing.unlink(missing_ok=True)
    started = time.perf_counter()
    record = run_trial(world, _config(online), seed)
    wall = time.perf_counter() - started
    slam = float(record.metadata["trial"]["slam_seconds"])
    inside = float(timing.read_text()) if online else slam  # the client's own GMapping seconds
    return wall, slam, inside, record


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", nargs="+", default=["office_small_01"])
    parser.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    args = parser.parse_args()

    from slamtrials.worlds import load_world

    print(f"CPU: {cpu_model()}; NUMBA_NUM_THREADS={os.environ['NUMBA_NUM_THREADS']}; one process, interleaved")
    timing = Path(tempfile.mkdtemp(prefix="bench-online-")) / "client_seconds.txt"
    os.environ["ONLINE_GMAPPING_SECONDS"] = str(timing)  # the client writes its GMapping seconds there
    warm = load_world("office_small_01")
    for online in (False, True):  # compile / load every kernel once
        _trial(warm, online, 0, timing)
    print(
        f"{'world':<16} {'seed':>4} {'frames':>6} {'wall in':>8} {'wall prog':>9} {'ratio':>6} "
        f"{'slam in':>8} {'client':>7} {'protocol ms/frame':>17}  same run"
    )
    totals = np.zeros(6)
    for name in args.worlds:
        world = load_world(name)
        for seed in args.seeds:
            wall_a, slam_a, _, a = _trial(world, False, seed, timing)
            wall_b, slam_b, client, b = _trial(world, True, seed, timing)
            same = len(a) == len(b) and _digest(a) == _digest(b)
            protocol = 1000.0 * (slam_b - client) / len(a)
            print(
                f"{name:<16} {seed:>4} {len(a):>6} {wall_a:>8.2f} {wall_b:>9.2f} {wall_b / wall_a:>6.3f} "
                f"{slam_a:>8.2f} {client:>7.2f} {protocol:>17.2f}  {'yes' if same else 'NO'}",
                flush=True,
            )
            totals += (wall_a, wall_b, slam_a, slam_b, client, len(a))
    wall_a, wall_b, slam_a, slam_b, client, frames = totals
    print(
        f"total: {int(frames)} frames; wall: in-process {wall_a:.1f} s, program {wall_b:.1f} s, ratio {wall_b / wall_a:.3f}; "
        f"SLAM per frame: in-process {1000 * slam_a / frames:.2f} ms, the client's GMapping {1000 * client / frames:.2f} ms, "
        f"protocol and the client's start {1000 * (slam_b - client) / frames:.2f} ms "
        f"({100 * (slam_b - client) / slam_a:.1f} % of the in-process SLAM time)"
    )


if __name__ == "__main__":
    main()
