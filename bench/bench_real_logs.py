"""SLAM repeated on every real log with relations in the shared data: spread, divergence and cost per log.

Run: ``SLAMTRIALS_SHARED=<shared> .venv/bin/python bench/bench_real_logs.py [--seeds 10] [--workers 2]
[--algorithm gmapping] [--set key=value ...] [--logs mit-csail fr079]``. Every sub-folder of
``<shared>/data`` with a ``*.relations`` file and a CARMEN log (``.clf``, ``.clf.gz``, ``.clf.bz2``) is
one dataset. Each runs ``--seeds`` times (seeds 0..N-1, in parallel, :func:`slamtrials.repeat.repeat_slam`)
with the algorithm's defaults (GMapping: slam_gmapping's) unless ``--set`` overrides them, and is scored
on its relations as the Freiburg tool scores it. Prints a Markdown table: mean and sample std of the
per-run mean translational and rotational errors, the share of diverged runs (above 5 x the median),
the SLAM updates and the wall time per run; the latest figures are kept in bench/RESULTS.md
("Real logs"), next to the published GMapping figures (50 particles, Kuemmerle et al. 2009).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

from benchutil import cpu_model  # noqa: E402
from slamtrials.cli.slam import parse_settings  # noqa: E402
from slamtrials.io.relations import read_relations  # noqa: E402
from slamtrials.repeat import RepeatSettings, repeat_slam, write_repeat_outputs  # noqa: E402
from slamtrials.slamrun import load_recording  # noqa: E402

#: Published GMapping figures (50 particles), Kuemmerle et al. 2009, via the shared data's SOURCES.md.
PUBLISHED = {"mit-csail": "0.049 +- 0.049", "fr079": "0.061 +- 0.044"}
LOG_SUFFIXES = (".clf", ".clf.gz", ".clf.bz2", ".log", ".log.gz", ".log.bz2")


def shared_data() -> Path:
    """``$SLAMTRIALS_SHARED/data``, else ``../shared/data`` beside the repository."""
    root = os.environ.get("SLAMTRIALS_SHARED")
    base = Path(root) if root else Path(__file__).resolve().parents[2] / "shared"
    return base / "data"


def datasets(data: Path, names: list[str] | None) -> list[tuple[str, Path, Path]]:
    """``(name, log, relations)`` of every dataset folder (or of ``names`` only), sorted by name."""
    found = []
    for folder in sorted(p for p in data.iterdir() if p.is_dir()):
        if names and folder.name not in names:
            continue
        relations = sorted(folder.glob("*.relations"))
        logs = sorted(p for p in folder.iterdir() if p.name.endswith(LOG_SUFFIXES))
        if relations and logs:
            found.append((folder.name, logs[0], relations[0]))
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--algorithm", default="gmapping")
    parser.add_argument("--preset", default=None)
    parser.add_argument("--set", dest="settings", action="append", default=[])
    parser.add_argument("--logs", nargs="*", default=None, help="dataset folder names (default: all)")
    parser.add_argument("--out", type=Path, default=None, help="write each dataset's outputs under OUT/<name>")
    args = parser.parse_args()
    data = shared_data()
    if not data.is_dir():
        print(f"no shared data at {data}; set SLAMTRIALS_SHARED", file=sys.stderr)
        return 2
    overrides = parse_settings(args.settings)
    print(
        f"# Real logs: {args.algorithm} {args.preset or 'defaults'} {overrides or ''}, seeds 0..{args.seeds - 1}, "
        f"{args.workers or os.cpu_count()} workers; {cpu_model()}\n"
    )
    print(
        "| log | frames | runs | eps_t mean +- std (m) | eps_r mean +- std (rad) | diverged (> 5 x median) "
        "| median eps_t (m) | updates | s per run | published GMapping (m) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, log, relations_path in datasets(data, args.logs):
        record = load_recording(log)
        relations = read_relations(relations_path)
        settings = RepeatSettings(algorithm=args.algorithm, preset=args.preset, overrides=overrides, runs=args.seeds)
        started = time.perf_counter()
        result = repeat_slam(
            record, relations, settings, workers=args.workers, source=str(log), relations_source=str(relations_path)
        )
        wall = time.perf_counter() - started
        if args.out is not None:
            write_repeat_outputs(result, args.out / name, overwrite=True)
        runs = result.runs
        st, sr, d = result.stats_t, result.stats_r, result.diverged
        median = statistics.median(r.eps_t for r in runs)
        per_run = sum(r.seconds for r in runs) / len(runs)
        print(
            f"| {name} | {len(record)} | {len(runs)} | {st.mean:.3f} +- {st.std_sample:.3f} | {sr.mean:.3f} +- {sr.std_sample:.3f} "
            f"| {int(d.diverged.sum())} of {len(runs)} (> {d.threshold:.3f} m) | {median:.3f} "
            f"| {runs[0].updates} | {per_run:.0f} | {PUBLISHED.get(name, '-')} |",
            flush=True,
        )
        print(
            f"<!-- {name}: per-seed eps_t {[round(r.eps_t, 4) for r in runs]}; {wall:.0f} s wall in all -->", flush=True
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
