"""The validation table of issue 32, item 5: on every real log, the default profile, the profile fitted on
the other logs and the log's own split-half profile, in one command.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/validation_table.py [--runs 5] [--out DIR]
[--log NAME LOG RELATIONS [KEY=VALUE ...]] [--only NAME] [--profiles NAME|FILE.yaml ...]``.

For each log the algorithm (GMapping, its defaults plus the log's overrides) runs once on the real log
(seed 0); that run's path and map are the replica and the laser's reference in the log's calibration
(``slamtrials calibrate --relations``, bootstrap 100: the odometry fitted against the log's relations). Rows per log, each ``--runs`` replicas (seeds 0 to N-1)
scored on the real relations' time pairs (:func:`slamtrials.validation.validate`, one core):

* ``default``: :data:`slamtrials.sim.profiles.DEFAULT_PROFILE`, the profile every command uses;
* ``other logs``: the mean (:func:`slamtrials.sim.profiles.mean_profile`) of the fits of every other log
  given (a log given alone has none);
* ``own split-half``: the log's first half (by time) calibrated, its second half validated with that
  profile (:func:`slamtrials.validation.split.split_validate`): the real error is then the second half's;
* one row per ``--profiles`` entry, if any.

Printed: one markdown row per log and profile, the real error next to the replicas' mean +- sample std and
their ratio, for translation and rotation, the raw odometry's real and simulated error, and each replica's
translational error; with ``--out`` every row's numbers are also written as the JSON ``slamtrials
validate --json`` writes (``<log>-<row>.json``). ``--only NAME`` prints the rows of that log alone (the
other logs are still calibrated, for its "other logs" row), so two processes can share the work.

Default logs: the shared MIT CSAIL log (GMapping's defaults) and fr079 (``linearUpdate=0.1``, the setting
that maps it: docs/real-datasets.md), from ``$SLAMTRIALS_SHARED/data`` (``../shared`` beside the
repository). ``--log NAME LOG RELATIONS [KEY=VALUE ...]`` replaces them (repeatable): held-out logs are
validated the same way. Issue 32's targets: the default profile's simulated eps_t within 0.6-1.4x of the
real one and eps_r within 0.5-2x, no replica diverging where the real log does not, the split-half own
profile within +-25 %.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("SLAMTRIALS_SHARED", HERE.parent.parent / "shared"))
DEFAULT_LOGS = (
    (
        "mit-csail",
        SHARED / "data" / "mit-csail" / "mit-csail.clf",
        SHARED / "data" / "mit-csail" / "mit-csail.relations",
        [],
    ),
    (
        "fr079",
        SHARED / "data" / "fr079" / "fr079.clf.bz2",
        SHARED / "data" / "fr079" / "fr079.relations",
        ["linearUpdate=0.1"],
    ),
)


def main() -> None:
    from slamtrials.calibration import CalibrationSettings, Reference, calibrate
    from slamtrials.cli.slam import parse_settings
    from slamtrials.cli.validate import resolve_profile_option
    from slamtrials.io.relations import read_relations
    from slamtrials.sim.profiles import BUNDLED_PROFILES, DEFAULT_PROFILE, mean_profile
    from slamtrials.slam.offline import run_over_recording
    from slamtrials.slamrun import load_recording
    from slamtrials.validation import ValidationSettings, check_belong, validate
    from slamtrials.validation.split import split_validate

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="replicas per log and row")
    parser.add_argument("--profiles", nargs="+", default=[], help="extra rows: bundled names or YAML files")
    parser.add_argument(
        "--log", nargs="+", action="append", metavar="ARG", help="NAME LOG RELATIONS [KEY=VALUE ...] (repeatable)"
    )
    parser.add_argument("--only", help="print the rows of this log only")
    parser.add_argument("--out", type=Path, help="folder for one JSON per row")
    args = parser.parse_args()

    logs = DEFAULT_LOGS
    if args.log:
        for entry in args.log:
            if len(entry) < 3:
                parser.error("--log takes NAME LOG RELATIONS [KEY=VALUE ...]")
        logs = tuple((e[0], Path(e[1]), Path(e[2]), e[3:]) for e in args.log)
    if args.only is not None and args.only not in [name for name, *_ in logs]:
        parser.error(f"--only {args.only}: not one of the logs ({', '.join(name for name, *_ in logs)})")
    extra = [(name, resolve_profile_option(name)) for name in args.profiles]
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
    calibration = CalibrationSettings(bootstrap=100)

    print(f"runs {args.runs} per row; GMapping; reference seed 0; {time.strftime('%Y-%m-%d')}\n")
    loaded = {}
    for log_name, log, relations_file, settings in logs:
        overrides = parse_settings(settings) or None
        record = load_recording(log)
        relations = read_relations(relations_file)
        check_belong(record, relations, 0.1, log=str(log), relations_source=str(relations_file))
        started = time.perf_counter()
        reference = run_over_recording(record, "gmapping", overrides=overrides, seed=0)
        source = f"gmapping final estimate and map (seed 0, {', '.join(settings) or 'defaults'})"
        fit = calibrate(
            record,
            Reference.from_grid(reference.estimate_per_frame(record), reference.occupancy, source),
            calibration,
            relations=relations,
            relations_source=str(relations_file),
        )
        profile = fit.profile(f"{log_name}-fit", f"slamtrials calibrate of {log.name} against {source}")
        loaded[log_name] = (log, relations_file, record, relations, overrides, reference, profile)
        print(f"{log_name}: reference run and calibration in {time.perf_counter() - started:.0f} s", flush=True)

    header = (
        "| log | profile | eps_t real (m) | eps_t simulated (m) | ratio | eps_r real (rad) | eps_r simulated (rad) "
        "| ratio | odometry real / simulated (m) | per replica eps_t (m) |"
    )
    rows = [header, "|" + "---|" * 10]
    for log_name, (log, relations_file, record, relations, overrides, reference, _) in loaded.items():
        if args.only is not None and log_name != args.only:
            continue
        settings = ValidationSettings(overrides=overrides, runs=args.runs)
        others = [fit for name, (*_, fit) in loaded.items() if name != log_name]
        candidates = [(f"default ({DEFAULT_PROFILE})", BUNDLED_PROFILES[DEFAULT_PROFILE])]
        if others:
            names = "+".join(name for name in loaded if name != log_name)
            candidates.append((f"other logs ({names})", mean_profile("other-logs", f"mean of {names}", others)))
        candidates.extend(extra)
        for row_name, profile in candidates:
            started = time.perf_counter()
            result = validate(
                record,
                relations,
                profile,
                settings,
                reference=reference,
                log=str(log),
                relations_source=str(relations_file),
            )
            rows.append(_row(log_name, row_name, result.to_dict()))
            print(f"{log_name} / {row_name}: {time.perf_counter() - started:.0f} s", flush=True)
            _write(args.out, log_name, row_name, result.to_dict())
        started = time.perf_counter()
        split = split_validate(
            record,
            relations,
            settings,
            calibration,
            profile_name=f"{log_name}-first-half",
            log=str(log),
            relations_source=str(relations_file),
        )
        row_name = f"own split-half (cut at {split.halves.split_t - record.t[0]:.0f} s)"
        rows.append(_row(log_name, row_name, split.validation.to_dict()))
        print(f"{log_name} / {row_name}: {time.perf_counter() - started:.0f} s", flush=True)
        _write(args.out, log_name, "split-half", split.validation.to_dict())
    print()
    print("\n".join(rows))


def _row(log_name: str, row_name: str, doc: dict) -> str:
    """One markdown row of the table from a validation's JSON."""
    slam, odometry = doc["slam"], doc["odometry"]
    t, r = slam["translational_m"], slam["rotational_rad"]
    replicas = ", ".join(_num(v, 3) for v in t["per_replica"])
    odo = odometry["translational_m"]
    return (
        f"| {log_name} | {row_name} | {_num(t['real'])} | {_num(t['simulated_mean'])} +- "
        f"{_num(t['simulated_std'])} | {_ratio(t)} | {_num(r['real'])} | {_num(r['simulated_mean'])} +- "
        f"{_num(r['simulated_std'])} | {_ratio(r)} | {_num(odo['real'], 2)} / {_num(odo['simulated_mean'], 2)} | "
        f"{replicas} |"
    )


def _write(out: Path | None, log_name: str, row_name: str, doc: dict) -> None:
    if out is not None:
        stem = row_name.split(" ")[0] if not row_name.endswith((".yaml", ".yml")) else Path(row_name).stem
        (out / f"{log_name}-{stem}.json").write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def _num(value: float | None, digits: int = 4) -> str:
    """A number of the validation JSON (None where it was not a number) as table text."""
    return "-" if value is None else f"{value:.{digits}f}"


def _ratio(error: dict) -> str:
    """Simulated mean over real error, two decimals ("-" when either is missing)."""
    if error["simulated_mean"] is None or not error["real"]:
        return "-"
    return f"{error['simulated_mean'] / error['real']:.2f}"


if __name__ == "__main__":
    import sys

    from slamtrials.errors import SlamtrialsError

    try:
        main()
    except SlamtrialsError as exc:  # bad input: one line, exit status 2, as the CLI does
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
