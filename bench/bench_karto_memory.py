"""Memory of karto's graph and scans after a whole trial (issue 23, point 4).

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_karto_memory.py [--world multiwing_large_01] [--seed 2]``.

One trial with karto (slam_toolbox's defaults) online, the paper's robot and laser, on ``--world``
(default: the largest bundled world, multiwing_large_01, 9,892 m^2 free; seed 2 by default, the run of
bench/RESULTS.md). The trial's karto object is
caught as :func:`slamtrials.trial.run.run_trial` builds it, and after the trial its memory is counted
by walking its attributes: every numpy array's ``nbytes`` plus ``sys.getsizeof`` of every other object
(lists, dataclasses, floats), each object once. Reported per part: the nodes' scans (their ranges, the
readings the matcher takes and the in-range flags), the rest of the nodes, the edges, the map (the optimized map's grids), the two
scan matchers' lookup grids, the per-frame lists, and the process's peak resident memory (whole
process: simulator, explorer, recorded frames, SLAM) from ``getrusage``. No tracemalloc: it would slow
the trial several times over and count the simulator and the recording as well.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import resource  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import fields, is_dataclass  # noqa: E402

import numpy as np  # noqa: E402

from bench_trial import resolve  # noqa: E402
from benchutil import cpu_model  # noqa: E402


def deep_size(obj, seen: set[int]) -> int:
    """Bytes held by ``obj`` and everything it refers to that ``seen`` does not hold yet (numpy: nbytes)."""
    if id(obj) in seen:
        return 0
    seen.add(id(obj))
    if isinstance(obj, np.ndarray):
        base = obj.base if obj.base is not None else None
        return obj.nbytes + (deep_size(base, seen) - obj.nbytes if isinstance(base, np.ndarray) else 0)
    size = sys.getsizeof(obj)
    if isinstance(obj, dict):
        size += sum(deep_size(k, seen) + deep_size(v, seen) for k, v in obj.items())
    elif isinstance(obj, (list, tuple, set, frozenset)):
        size += sum(deep_size(item, seen) for item in obj)
    elif is_dataclass(obj):
        size += sum(deep_size(getattr(obj, f.name), seen) for f in fields(obj))
    elif hasattr(obj, "__dict__") and not isinstance(obj, type):
        size += deep_size(vars(obj), seen)
    return size


def mb(n: int) -> str:
    return f"{n / 1e6:,.1f}"


def main() -> None:
    import slamtrials.trial.run as trial_run
    from slamtrials.trial import TrialConfig
    from slamtrials.worlds import load_world

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="multiwing_large_01")
    parser.add_argument("--seed", type=int, default=2)
    args = parser.parse_args()

    caught = []
    original = trial_run.get_algorithm

    def catching(name):
        cls = original(name)

        def build(*a, **k):
            instance = cls(*a, **k)
            caught.append(instance)
            return instance

        return build

    trial_run.get_algorithm = catching
    world = load_world(resolve(args.world))
    config = TrialConfig.from_dict({"slam": {"algorithm": "karto", "preset": None}})
    started = time.perf_counter()
    info = trial_run.run_trial(world, config, args.seed).metadata["trial"]
    wall = time.perf_counter() - started
    karto = caught[-1]
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024

    nodes, edges = karto.graph.nodes, karto.graph.edges
    seen: set[int] = set()
    scans = sum(deep_size(n.ranges, seen) + deep_size(n.readings, seen) + deep_size(n.within, seen) for n in nodes)
    node_rest = sum(deep_size(n, seen) for n in nodes) + deep_size(nodes, seen)
    edge_bytes = deep_size(edges, seen) + deep_size(karto.graph, seen)
    matchers = {name: deep_size(getattr(karto, name), seen) for name in ("sequential", "loop_matcher")}
    map_bytes = deep_size(karto.map, seen)
    frames = sum(deep_size(getattr(karto, name), seen) for name in ("_t", "_odometry", "_anchor", "_estimates"))
    rest = deep_size(karto, seen)
    beams = nodes[0].ranges.shape[0]

    print(
        f"CPU: {cpu_model()}; date {time.strftime('%Y-%m-%d')}; world {world.name}, seed {args.seed}: "
        f"{info['termination_reason']}, {info['duration_s']:.0f} s simulated, {wall:.0f} s wall, "
        f"mapped {info['mapped_fraction']:.3f}\n"
    )
    print(
        f"{len(nodes):,} nodes of {beams} beams, {len(edges):,} edges, {karto.loop_closures} loop closures, "
        f"{len(karto._t):,} frames\n"
    )
    print("| part | MB | per node (kB) |")
    print("|---|---:|---:|")
    rows = [
        ("nodes' scans (ranges float32, readings float64, in-range flags)", scans),
        ("nodes' other fields (poses, odometry, objects)", node_rest),
        ("edges (mean, covariance, objects) and graph", edge_bytes),
        ("sequential matcher (lookup grid, kernels)", matchers["sequential"]),
        ("loop matcher (lookup grid, kernels)", matchers["loop_matcher"]),
        ("map builder (count grids, traced poses)", map_bytes),
        ("per-frame lists (times, odometry, anchors, estimates)", frames),
        ("the rest", rest),
    ]
    total = sum(b for _, b in rows)
    for name, b in rows + [("karto in all", total)]:
        print(f"| {name} | {mb(b)} | {b / len(nodes) / 1e3:.2f} |")
    print(f"\nPeak resident memory of the whole process (getrusage): {mb(peak)} MB")


if __name__ == "__main__":
    main()
