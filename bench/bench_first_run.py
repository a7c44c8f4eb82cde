"""First run against later runs: wall time of ``slamtrials trial`` with an empty numba cache, then again
with the cache that first run filled.

Run: ``.venv/bin/python bench/bench_first_run.py [--world office_small_01] [--seed 1] [--repeats 2]``.

Each repeat starts from a fresh, empty ``NUMBA_CACHE_DIR`` (cold: every kernel the trial needs is
compiled) and then runs the same command again with that cache (warm: every kernel is loaded from it).
The commands run as separate processes, as a user runs them, one core each. Reported per run: the wall
time of the whole process, the trial's own wall time as ``run.json`` records it (simulation, SLAM and
exploration, including any compiling), the rest (interpreter, imports, loading the world, writing the
run folder and its picture), the process's CPU time (what a loaded machine changes least) and how many
kernels it compiled (``-v`` logs each; a terminal would also get the one-line notice). The start-up
alone (``slamtrials --version``: interpreter and the CLI's imports) is measured once, and the 1-minute
load average is printed so that figures taken on a shared machine can be read.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchutil import cpu_model

CLI = "import sys; from slamtrials.cli.main import main; sys.argv[0] = 'slamtrials'; main()"


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(args: list[str], cache: Path) -> tuple[float, float, str]:
    """Wall time (s), CPU time (s) and stderr of ``slamtrials -v ARGS`` with numba's cache in ``cache``."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    cpu = _children_cpu()
    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", CLI, "-v", *args], env=env, capture_output=True, text=True, check=False
    )
    wall = time.perf_counter() - started
    if done.returncode != 0:
        sys.exit(f"slamtrials {' '.join(args)} failed ({done.returncode}):\n{done.stderr}")
    return wall, _children_cpu() - cpu, done.stderr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="office_small_01")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()

    print(f"CPU: {cpu_model()}, {os.cpu_count()} cores; python {sys.version.split()[0]}")
    with tempfile.TemporaryDirectory(prefix="bench-first-run-") as tmp:
        root = Path(tmp)
        startup, _, _ = run(["--version"], root / "version-cache")
        print(f"start-up (slamtrials --version): {startup:.2f} s")
        print(f"{'run':>6} {'wall s':>7} {'CPU s':>7} {'trial s':>8} {'rest s':>7} {'kernels compiled':>17}  load avg")
        for repeat in range(args.repeats):
            cache = root / f"cache-{repeat}"
            for kind in ("cold", "warm"):
                out = root / f"trial-{repeat}-{kind}"
                wall, cpu, stderr = run(
                    ["trial", "--world", args.world, "--seed", str(args.seed), "--out", str(out)], cache
                )
                trial_wall = json.loads((out / "run.json").read_text())["trial"]["wall_time_s"]
                compiled = stderr.count("INFO slamtrials.compilewatch: compiled ")
                print(
                    f"{kind:>6} {wall:7.1f} {cpu:7.1f} {trial_wall:8.1f} {wall - trial_wall:7.1f} {compiled:17d}  "
                    f"{os.getloadavg()[0]:.1f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
