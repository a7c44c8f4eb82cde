"""Issue 23, point 5: GMapping (paper preset) against karto (defaults), from scratch, into one folder.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_karto_vs_gmapping.py [OUT] [--workers 1] [--online]
[--profile paper]``.

1. ``slamtrials campaign run bench/configs/karto_vs_gmapping/gmapping.yaml --out OUT/gmapping``: online
   GMapping with the ``paper`` preset explores the demo's three bundled worlds and three small real maps
   (``../shared/worlds/real``), the campaign's default error profile (``realistic``), 8 runs per world
   then the run-count rule up to 10.
2. ``slamtrials campaign replay OUT/gmapping --algorithm karto --out OUT/karto_replay``: karto with its
   defaults on the same recorded data, run by run (no simulation).
3. ``slamtrials compare OUT/gmapping OUT/karto_replay``: paired tests per world, Holm-corrected p and
   intervals, Stouffer's overall test, the Fig. 6 trap (printed; also ``OUT/karto_replay/report/``).
4. With ``--online``: ``bench/configs/karto_vs_gmapping/karto.yaml``, a campaign where karto drives the
   exploration (``OUT/karto_online``), and ``slamtrials compare OUT/gmapping OUT/karto_online``
   (unpaired: Welch).

``--profile paper`` runs all of it with the paper's error profile instead (noise-free laser, the
paper's odometry bias) in the same folder layout: give it another ``OUT``.

Each step resumes what a previous call left in ``OUT`` (a finished campaign is not run again). The
real maps are found through ``$SLAMTRIALS_SHARED`` (default: ``../shared`` next to the repository),
written into a copy of each config in ``OUT``. Figures of the last run: docs/karto.md, "Comparison
with GMapping", and bench/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

HERE = Path(__file__).resolve().parent
CONFIGS = HERE / "configs" / "karto_vs_gmapping"
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", HERE.parent.parent / "shared"))
REAL_PREFIX = "../../../../shared/"


def localized_config(name: str, out: Path, profile: str | None = None) -> Path:
    """``CONFIGS/name`` with its real-map entries pointing into ``$SLAMTRIALS_SHARED`` (and ``sim.profile``
    set to ``profile`` if given), saved in ``out``."""
    data = yaml.safe_load((CONFIGS / name).read_text(encoding="utf-8"))
    if profile is not None:
        data.setdefault("sim", {})["profile"] = profile
    worlds = []
    for entry in data["worlds"]:
        if entry.startswith(REAL_PREFIX):
            path = SHARED / entry[len(REAL_PREFIX) :]
            if not path.is_file():
                sys.exit(f"{CONFIGS / name}: world {entry!r}: no {path} (set SLAMTRIALS_SHARED)")
            entry = str(path)
        worlds.append(entry)
    data["worlds"] = worlds
    target = out / f"config-{name}"
    target.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return target


def slamtrials(*args: str) -> None:
    """Run one ``slamtrials`` command with this interpreter; stop on failure."""
    command = [sys.executable, "-m", "slamtrials", *args]
    print(f"\n$ slamtrials {' '.join(args)}", flush=True)
    started = time.perf_counter()
    done = subprocess.run(command, check=False)
    print(f"({time.perf_counter() - started:.0f} s)", flush=True)
    if done.returncode != 0:
        sys.exit(done.returncode)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "out",
        type=Path,
        nargs="?",
        default=None,
        help="folder of the campaigns (created; resumed if it exists; "
        "default: a new temporary folder, as bench/run_all.py runs it)",
    )
    parser.add_argument("--workers", "-j", type=int, default=1, help="worker processes (1 or 2 on a shared machine)")
    parser.add_argument("--online", action="store_true", help="also a campaign where karto explores, compared unpaired")
    parser.add_argument(
        "--profile", default=None, help="error profile of every campaign (default: the configs', realistic), e.g. paper"
    )
    args = parser.parse_args()
    out = (Path(tempfile.mkdtemp(prefix="karto_vs_gmapping-")) if args.out is None else args.out).resolve()
    print(f"campaigns in {out}", flush=True)
    out.mkdir(parents=True, exist_ok=True)
    workers = str(args.workers)

    slamtrials(
        "campaign",
        "run",
        str(localized_config("gmapping.yaml", out, args.profile)),
        "--out",
        str(out / "gmapping"),
        "-j",
        workers,
    )
    slamtrials(
        "campaign",
        "replay",
        str(out / "gmapping"),
        "--algorithm",
        "karto",
        "--out",
        str(out / "karto_replay"),
        "-j",
        workers,
    )
    slamtrials("compare", str(out / "gmapping"), str(out / "karto_replay"))
    if args.online:
        config = localized_config("karto.yaml", out, args.profile)
        slamtrials("campaign", "run", str(config), "--out", str(out / "karto_online"), "-j", workers)
        slamtrials("compare", str(out / "gmapping"), str(out / "karto_online"))


if __name__ == "__main__":
    main()
