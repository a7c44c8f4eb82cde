"""Run every benchmark in bench/ (files named bench_*.py), one after the other, one core each.

Each benchmark prints its own figures; copy them into bench/RESULTS.md with the date and machine.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
    env = dict(os.environ, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    status = 0
    for script in sorted(HERE.glob("bench_*.py")):
        print(f"== {script.name}", flush=True)
        status |= subprocess.call([sys.executable, str(script)], env=env)
    return status


if __name__ == "__main__":
    sys.exit(main())
