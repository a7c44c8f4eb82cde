"""The paper's own validation settings (Section IV, Tables II and III) replayed in slamtrials' simulator.

Run: ``NUMBA_NUM_THREADS=1 .venv/bin/python bench/bench_paper_validation.py [--seeds 10] [--profile NAME ...]
[--jobs 1] [--out DIR]``; ``--report`` prints the table of ``DIR/trials.csv`` without running anything.

The settings are the campaign configs in ``bench/configs/paper_validation/``: ``table2_hall.yaml`` (the
L-shaped 10 x 12 m industrial hall, empty and furnished; 80 deg / 1 deg / 30 m laser; odometry bias up
to 0.01 m/m and 2 deg/rad) and ``table3_lab.yaml`` (the 9 x 9 m AIRLab; SICK LMS100: 270 deg / 0.25 deg /
20 m; up to 0.01 m/m and 4 deg/rad), on the bundled replica worlds ``paper_hall_empty``,
``paper_hall_furnished`` and ``paper_lab``, whose layouts are guesses from the paper's text. Each world
gets one trial per seed 0 .. N-1 (:func:`slamtrials.trial.run_trial`: online GMapping with the
``paper`` preset, as the paper used, frontier exploration, the paper's termination rule), scored as a
campaign scores a run (:func:`slamtrials.campaign.score.score_run` with the config's metric settings,
the run's seed drawing its relation set). The table gives, per world and profile, the mean +- sample
standard deviation of the runs' ``eps_t`` (m) and ``eps_r`` (rad) next to the paper's real-robot and
simulated figures, and the raw odometry's errors on the same relations.

``--profile NAME`` (repeatable) sets ``sim.profile: NAME`` (a bundled error profile such as ``paper``
or ``realistic``, or a profile YAML file) in every config, one set of trials per profile; an unknown
profile is refused in one line (exit 2). The configs write the laser geometry and the per-run bias
ranges explicitly, and those override the profile's, so a profile adds its noise, short readings,
dropouts, random odometry noise and slips to each setting's own robot. Without ``--profile`` the
configs run as written: they name no profile, so they get the default of every command, ``realistic``
(:data:`slamtrials.sim.profiles.DEFAULT_PROFILE`); ``--profile paper`` is the paper's Stage set-up
(noise-free laser, constant per-run odometry bias). The table's profile column is the profile with its
overrides (``realistic + 2 overrides``: the two bias ranges), and the script prints it for each config
(``profile: ...``) before the trials. ``--set FIELD=VALUE``
(repeatable, VALUE read as YAML) changes a field of every config for a side measurement, e.g.
``--set sim.laser.fov=4.71238898038469`` or ``--set "sim.odometry.bias_linear_range=[-0.005, 0.005]"``
(use another ``--out``: the CSV does not record the change).

Every trial appends one row to ``DIR/trials.csv`` (default ``results/paper_validation``, which git
ignores) as soon as it ends, so ``--resume`` continues an interrupted run; the Markdown table is
printed and written to ``DIR/table.md``.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import csv  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from concurrent.futures import ProcessPoolExecutor  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

from benchutil import cpu_model  # noqa: E402

HERE = Path(__file__).resolve().parent
CONFIGS = HERE / "configs" / "paper_validation"
DEFAULT_CONFIGS = (CONFIGS / "table2_hall.yaml", CONFIGS / "table3_lab.yaml")
FIELDS = (
    "config",
    "world",
    "profile",
    "seed",
    "reason",
    "mapped",
    "observed",
    "duration_s",
    "wall_s",
    "eps_t",
    "eps_r",
    "odometry_eps_t",
    "odometry_eps_r",
    "relations",
    "error",
)


@dataclass(frozen=True)
class PaperFigures:
    """The paper's numbers for one setting: mean errors (m, rad) and, where Table III gives them, their std."""

    table: str
    real_t: float
    real_r: float
    sim_t: float
    sim_r: float
    real_st: float | None = None
    real_sr: float | None = None
    sim_st: float | None = None
    sim_sr: float | None = None


#: Table II (dataset [26]: real robot, and the mean of 10 simulated runs) and Table III (Robocom, 10 real
#: and 10 simulated runs, with standard deviations).
PAPER: dict[str, PaperFigures] = {
    "paper_hall_empty": PaperFigures("II", real_t=0.189, real_r=0.058, sim_t=0.223, sim_r=0.030),
    "paper_hall_furnished": PaperFigures("II", real_t=0.267, real_r=0.070, sim_t=0.245, sim_r=0.045),
    "paper_lab": PaperFigures(
        "III",
        real_t=0.086,
        real_r=0.066,
        sim_t=0.101,
        sim_r=0.022,
        real_st=0.026,
        real_sr=0.010,
        sim_st=0.019,
        sim_sr=0.004,
    ),
}


@dataclass(frozen=True)
class Summary:
    """The runs of one (world, profile): how many, their mean and sample std of each error, how they ended."""

    world: str
    profile: str
    runs: int
    failed: int
    eps_t: tuple[float, float]
    eps_r: tuple[float, float]
    odometry_t: tuple[float, float]
    odometry_r: tuple[float, float]
    reasons: str
    mapped_min: float
    observed_min: float
    wall_mean: float


def _mean_std(values: list[float]) -> tuple[float, float]:
    """Mean and sample standard deviation (n - 1; NaN for fewer than two values; both NaN for none)."""
    if not values:
        return math.nan, math.nan
    mean = math.fsum(values) / len(values)
    if len(values) < 2:
        return mean, math.nan
    return mean, math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (len(values) - 1))


def summarize(rows: list[dict]) -> list[Summary]:
    """Group CSV rows (strings or numbers) by (world, profile), in first-seen order; failed trials
    (an ``error``, or no ``eps_t``) are counted but not averaged."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for row in rows:
        groups.setdefault((str(row["world"]), str(row["profile"])), []).append(row)
    out = []
    for (world, profile), group in groups.items():
        ok = [r for r in group if not r.get("error") and str(r.get("eps_t", "")) not in ("", "nan")]

        def column(name: str, ok: list[dict] = ok) -> list[float]:
            return [float(r[name]) for r in ok]

        out.append(
            Summary(
                world=world,
                profile=profile,
                runs=len(ok),
                failed=len(group) - len(ok),
                eps_t=_mean_std(column("eps_t")),
                eps_r=_mean_std(column("eps_r")),
                odometry_t=_mean_std(column("odometry_eps_t")),
                odometry_r=_mean_std(column("odometry_eps_r")),
                reasons=", ".join(sorted({str(r["reason"]) for r in group})),
                mapped_min=min((float(r["mapped"]) for r in ok), default=math.nan),
                observed_min=min((float(r["observed"]) for r in ok), default=math.nan),
                wall_mean=_mean_std(column("wall_s"))[0],
            )
        )
    return out


def _pm(mean: float, std: float | None, digits: int = 3) -> str:
    if math.isnan(mean):
        return "-"
    if std is None or math.isnan(std):
        return f"{mean:.{digits}f}"
    return f"{mean:.{digits}f} +- {std:.{digits}f}"


def markdown_table(summaries: list[Summary]) -> str:
    """The comparison table: per (world, profile) the measured errors, then the paper's real and simulated ones."""
    lines = [
        "| Table | world | profile | runs | eps_t m | eps_r rad | paper real eps_t | paper real eps_r "
        "| paper sim eps_t | paper sim eps_r | odometry eps_t m | odometry eps_r rad | end | observed (min) | mapped (min) | wall s |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|",
    ]
    for s in summaries:
        paper = PAPER.get(s.world)
        runs = f"{s.runs}" + (f" (+{s.failed} failed)" if s.failed else "")
        if paper is None:
            theirs = ["-"] * 4
        else:
            theirs = [
                _pm(paper.real_t, paper.real_st),
                _pm(paper.real_r, paper.real_sr),
                _pm(paper.sim_t, paper.sim_st),
                _pm(paper.sim_r, paper.sim_sr),
            ]
        mapped = "-" if math.isnan(s.mapped_min) else f"{s.mapped_min:.3f}"
        observed = "-" if math.isnan(s.observed_min) else f"{s.observed_min:.3f}"
        wall = "-" if math.isnan(s.wall_mean) else f"{s.wall_mean:.1f}"
        lines.append(
            f"| {paper.table if paper else '-'} | {s.world} | {s.profile} | {runs} | {_pm(*s.eps_t)} | {_pm(*s.eps_r)} | "
            + " | ".join(theirs)
            + f" | {_pm(*s.odometry_t)} | {_pm(*s.odometry_r)} | {s.reasons} | {observed} | {mapped} | {wall} |"
        )
    return "\n".join(lines)


def _set(data: dict, dotted: str, value: object) -> None:
    """Set ``data[a][b][c] = value`` for ``dotted = "a.b.c"``, making the sections that are missing."""
    *sections, key = dotted.split(".")
    for name in sections:
        section = data.get(name)
        if not isinstance(section, dict):
            section = data[name] = {}
        data = section
    data[key] = value


def load_config(path: Path, profile: str | None, overrides: tuple[tuple[str, object], ...] = ()):
    """The campaign config of ``path``, with ``sim.profile`` set when ``profile`` is given and the
    ``(dotted.field, value)`` overrides applied.

    Raises
    ------
    ConfigError, FormatError
        One line naming the file and the field (e.g. a ``sim.profile`` this version does not know).
    """
    from slamtrials.campaign.config import CampaignConfig
    from slamtrials.campaign.profilefile import inline_profile_file
    from slamtrials.io.yamlfile import read_yaml_mapping

    data = read_yaml_mapping(path)
    if profile is not None:
        _set(data, "sim.profile", profile)
        data = inline_profile_file(data, Path.cwd())  # a profile file named on the command line
    for dotted, value in overrides:
        _set(data, dotted, value)
    return CampaignConfig.from_dict(data, source=str(path))


def parse_override(text: str) -> tuple[str, object]:
    """``FIELD=VALUE`` (VALUE read as YAML) as ``(FIELD, value)``; argparse reports a malformed one."""
    import yaml

    field, sep, value = text.partition("=")
    if not sep or not field.strip():
        raise argparse.ArgumentTypeError(f"expected FIELD=VALUE (e.g. sim.laser.fov=4.712), got {text!r}")
    try:
        return field.strip(), yaml.safe_load(value)
    except yaml.YAMLError:
        raise argparse.ArgumentTypeError(f"{text!r}: the value is not YAML") from None


def one_trial(
    config_path: str, world_name: str, profile: str | None, seed: int, overrides: tuple[tuple[str, object], ...] = ()
) -> dict:
    """Run and score one trial (in this or a worker process); a trial that fails is a row with its error."""
    from slamtrials.campaign.score import score_run
    from slamtrials.errors import SlamtrialsError
    from slamtrials.trial import run_trial
    from slamtrials.worlds import load_world

    config = load_config(Path(config_path), profile, overrides)
    row: dict = {
        "config": Path(config_path).name,
        "world": world_name,
        "profile": config.sim.profile_label,
        "seed": seed,
    }
    started = time.perf_counter()
    try:
        record = run_trial(load_world(world_name), config.trial_config(), seed)
        score = score_run(record, seed, config.metric)
    except SlamtrialsError as exc:
        return {**row, "reason": "error", "wall_s": round(time.perf_counter() - started, 2), "error": str(exc)}
    info = record.metadata["trial"]
    return {
        **row,
        "reason": info["termination_reason"],
        "mapped": round(info["mapped_fraction"], 4),
        "observed": round(info["observed_fraction"], 4),
        "duration_s": round(info["duration_s"], 1),
        "wall_s": round(time.perf_counter() - started, 2),
        "eps_t": f"{score.eps_t:.6f}",
        "eps_r": f"{score.eps_r:.6f}",
        "odometry_eps_t": f"{score.odometry.eps_t:.6f}",
        "odometry_eps_r": f"{score.odometry.eps_r:.6f}",
        "relations": len(score.relation_set),
        "error": "",
    }


def _read_rows(path: Path) -> list[dict]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configs", nargs="+", type=Path, default=list(DEFAULT_CONFIGS))
    parser.add_argument("--seeds", type=int, default=10, help="trials per world: seeds 0 .. N-1 (default 10)")
    parser.add_argument(
        "--profile",
        action="append",
        default=None,
        help="set sim.profile (a bundled error profile or a profile YAML file); repeat for several",
    )
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        type=parse_override,
        default=[],
        metavar="FIELD=VALUE",
        help="change a config field in every config, e.g. sim.laser.fov=4.712 (VALUE is YAML); repeatable",
    )
    parser.add_argument("--jobs", type=int, default=1, help="worker processes (default 1: one core)")
    parser.add_argument("--out", type=Path, default=HERE.parent / "results" / "paper_validation")
    parser.add_argument("--resume", action="store_true", help="keep the rows already in DIR/trials.csv")
    parser.add_argument("--report", action="store_true", help="only print the table of DIR/trials.csv")
    args = parser.parse_args()
    csv_path = args.out / "trials.csv"
    if args.report:
        print(markdown_table(summarize(_read_rows(csv_path))))
        return

    from slamtrials.errors import SlamtrialsError

    profiles: list[str | None] = list(args.profile) if args.profile else [None]
    overrides = tuple(args.overrides)
    jobs = []
    labels = {}  # (config, profile option) -> the profile label of its rows
    lines = []
    for path in args.configs:
        for profile in profiles:
            try:
                config = load_config(path, profile, overrides)
            except SlamtrialsError as exc:
                print(f"error: {exc}", file=sys.stderr)
                sys.exit(2)
            labels[(str(path), profile)] = config.sim.profile_label
            keys = ", ".join(o.key for o in config.sim.profile_overrides)
            lines.append(f"{path.name}: profile: {config.sim.profile_label}" + (f" ({keys})" if keys else ""))
            jobs += [
                (str(path), world, profile, seed, overrides) for world in config.worlds for seed in range(args.seeds)
            ]
    for line in lines:
        print(line)

    args.out.mkdir(parents=True, exist_ok=True)
    rows = _read_rows(csv_path) if args.resume and csv_path.is_file() else []
    done = {(r["config"], r["world"], r["profile"], int(r["seed"])) for r in rows}
    jobs = [j for j in jobs if (Path(j[0]).name, j[1], labels[(j[0], j[2])], j[3]) not in done]
    if not rows:
        with csv_path.open("w", newline="") as handle:
            csv.DictWriter(handle, FIELDS).writeheader()
    if overrides:
        print("settings changed: " + ", ".join(f"{k}={v!r}" for k, v in overrides))
    print(f"CPU: {cpu_model()}; {len(jobs)} trials to run ({len(rows)} done), {args.jobs} at a time", flush=True)
    started = time.perf_counter()

    def keep(row: dict) -> None:
        rows.append(row)
        with csv_path.open("a", newline="") as handle:
            csv.DictWriter(handle, FIELDS).writerow(row)
        what = row["error"] or f"eps_t {float(row['eps_t']):.3f} m, eps_r {float(row['eps_r']):.3f} rad"
        print(f"{row['world']} {row['profile']} seed {row['seed']}: {row['reason']}, {what} ({row['wall_s']} s)")

    if args.jobs <= 1:
        for job in jobs:
            keep(one_trial(*job))
    else:
        with ProcessPoolExecutor(max_workers=args.jobs) as pool:
            for row in pool.map(one_trial, *zip(*jobs)) if jobs else ():
                keep(row)
    table = markdown_table(summarize(rows))
    note = (
        f"- Measured {time.strftime('%Y-%m-%d')} on {os.cpu_count()} cores, CPU `{cpu_model()}`, "
        f"{args.jobs} trial(s) at a time, NUMBA_NUM_THREADS={os.environ.get('NUMBA_NUM_THREADS')}; "
        f"seeds 0..{args.seeds - 1}; {time.perf_counter() - started:.0f} s for {len(jobs)} trials."
    )
    (args.out / "table.md").write_text(table + "\n\n" + note + "\n", encoding="utf-8")
    print()
    print(table)
    print()
    print(note)


if __name__ == "__main__":
    main()
