"""``slamtrials export`` and ``slamtrials import``: a run folder to and from ROS bags, CARMEN logs and TUM files."""

from __future__ import annotations

import gzip
import shutil
import tempfile
import zlib
from enum import Enum
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from slamtrials.cli.main import make_console
from slamtrials.errors import ConfigError, FormatError


class ExportFormat(str, Enum):
    bag = "bag"
    bag2 = "bag2"
    carmen = "carmen"
    tum = "tum"


class TumSource(str, Enum):
    truth = "truth"
    odometry = "odometry"


class ImportFormat(str, Enum):
    auto = "auto"
    bag = "bag"
    carmen = "carmen"


class Pairing(str, Enum):
    interpolate = "interpolate"
    previous = "previous"


CARMEN_SUFFIXES = (".clf", ".log", ".carmen")
BAG_SUFFIXES = (".bag", ".mcap", ".db3")


def _check_out(out: Path, overwrite: bool) -> None:
    if out.exists() and not overwrite:
        raise ConfigError(f"{out}: already exists; choose another --out or pass --overwrite")


def _remove(out: Path) -> None:
    """Remove an existing output that a writer cannot replace by itself (a file where a folder goes)."""
    if out.is_dir() and not out.is_symlink():
        shutil.rmtree(out)
    elif out.exists():
        out.unlink()


def export_run(
    run: Annotated[Path, typer.Argument(metavar="RUN", help="Run folder (frames.npz + run.json).")],
    to: Annotated[ExportFormat, typer.Option("--to", "-t", help="bag: ROS 1 .bag; bag2: ROS 2 bag folder (MCAP); carmen: CARMEN log; tum: TUM trajectory.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="File (or ROS 2 bag folder) to write.")],
    what: Annotated[TumSource | None, typer.Option("--what", help="For --to tum: the ground truth (default) or the odometry.")] = None,
    time_origin: Annotated[int | None, typer.Option("--time-origin-ns", help="For bags: ROS stamp (ns) of t = 0; default 1 s.")] = None,
    compress: Annotated[bool, typer.Option("--compress", help="For bags: LZ4 chunks (ROS 1) or zstd MCAP chunks (ROS 2).")] = False,
    carmen_kind: Annotated[str, typer.Option("--carmen-kind", help="For --to carmen: ROBOTLASER1 (geometry on every line) or FLASER.")] = "ROBOTLASER1",
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace an existing --out.")] = False,
) -> None:
    """Export a run's laser, odometry and ground truth as a ROS bag (Stage topics), a CARMEN log or a TUM file."""
    from slamtrials.io.runfolder import read_run

    if what is not None and to is not ExportFormat.tum:
        raise ConfigError("--what applies to --to tum only")
    if (time_origin is not None or compress) and to not in (ExportFormat.bag, ExportFormat.bag2):
        raise ConfigError("--time-origin-ns and --compress apply to --to bag and --to bag2 only")
    if carmen_kind not in ("ROBOTLASER1", "FLASER"):
        raise ConfigError(f"--carmen-kind must be ROBOTLASER1 or FLASER, got {carmen_kind!r}")
    _check_out(out, overwrite)
    record = read_run(run)
    console = make_console()
    if to in (ExportFormat.bag, ExportFormat.bag2):
        from slamtrials.io.rosbag import DEFAULT_TIME_ORIGIN_NS, write_bag

        ros = 1 if to is ExportFormat.bag else 2
        if out.exists() and (out.is_dir() != (ros == 2)):
            _remove(out)
        origin = DEFAULT_TIME_ORIGIN_NS if time_origin is None else time_origin
        write_bag(out, record, ros=ros, time_origin_ns=origin, overwrite=overwrite, compress=compress)
        truth = "with" if np.isfinite(record.truth).all(axis=1).any() else "without"
        console.print(f"{out}: ROS {ros} bag, {len(record)} scans on /base_scan, /odom, /tf, {truth} /base_pose_ground_truth")
    elif to is ExportFormat.carmen:
        from slamtrials.io.carmen import carmen_from_run, write_carmen

        if not np.isfinite(record.truth).all():
            raise ConfigError(f"{run}: the run has no ground truth for every frame; a CARMEN laser line needs it (first pose triple)")
        try:
            write_carmen(out, carmen_from_run(record, kind=carmen_kind))
        except ValueError as exc:
            raise ConfigError(f"{run}: cannot be written as a CARMEN log: {exc}") from None
        console.print(f"{out}: CARMEN log, {len(record)} {carmen_kind} and ODOM lines (first pose = ground truth, second = odometry)")
    else:
        _export_tum(run, record, out, what or TumSource.truth, console)


def _export_tum(run: Path, record, out: Path, what: TumSource, console) -> None:
    from slamtrials.io.tum import write_tum
    from slamtrials.record import Trajectory

    poses = record.truth if what is TumSource.truth else record.odometry
    known = np.isfinite(poses).all(axis=1)
    if not known.any():
        raise ConfigError(f"{run}: the run has no {what.value} (a recording without ground truth?); try --what odometry")
    write_tum(out, Trajectory(t=np.asarray(record.t)[known], poses=np.asarray(poses)[known]))
    skipped = f" ({np.count_nonzero(~known)} frames without it skipped)" if not known.all() else ""
    frame = "world frame" if what is TumSource.truth else "odometry frame"
    console.print(f"{out}: TUM trajectory of the {what.value} ({frame}), {np.count_nonzero(known)} poses{skipped}")


def _import_format(path: Path, fmt: ImportFormat) -> ImportFormat:
    if fmt is not ImportFormat.auto:
        return fmt
    suffixes = [s.lower() for s in path.suffixes]
    if path.is_dir() or (suffixes and suffixes[-1] in BAG_SUFFIXES):
        return ImportFormat.bag
    if suffixes and (suffixes[-1] in CARMEN_SUFFIXES or suffixes[-1] == ".gz"):
        return ImportFormat.carmen
    if not path.exists():
        raise FormatError(path, "no such file or folder")
    with open(path, "rb") as handle:
        head = handle.read(16)
    return ImportFormat.bag if head.startswith((b"#ROSBAG", b"\x89MCAP")) else ImportFormat.carmen


def _read_carmen_file(path: Path):
    from slamtrials.io.carmen import read_carmen, run_from_carmen

    if path.suffix.lower() != ".gz":
        return run_from_carmen(read_carmen(path))
    with tempfile.TemporaryDirectory(prefix="slamtrials-import-") as tmp:
        plain = Path(tmp) / path.stem
        try:
            with gzip.open(path, "rb") as source, open(plain, "wb") as target:
                shutil.copyfileobj(source, target)
        except FileNotFoundError:
            raise FormatError(path, "no such file") from None
        except (OSError, EOFError, zlib.error) as exc:
            raise FormatError(path, f"not a readable gzip file ({exc})") from None
        try:
            record = run_from_carmen(read_carmen(plain))
        except FormatError as exc:  # name the file the user gave, with the line in the decompressed log
            raise FormatError(path, f"(decompressed) {exc.problem}", line=exc.line, offset=exc.offset) from None
    return record


def import_run(
    source: Annotated[Path, typer.Argument(metavar="FILE", help="ROS 1 .bag, ROS 2 bag folder or .mcap, or CARMEN log (.clf, .log, .gz).")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Run folder to write (frames.npz, run.json).")],
    fmt: Annotated[ImportFormat, typer.Option("--format", "-f", help="Input format; auto: from the name and first bytes.")] = ImportFormat.auto,
    scan_topic: Annotated[str | None, typer.Option("--scan-topic", help="Bag: sensor_msgs/LaserScan topic [default: /base_scan].")] = None,
    odom_topic: Annotated[str | None, typer.Option("--odom-topic", help="Bag: nav_msgs/Odometry topic [default: /odom].")] = None,
    truth_topic: Annotated[str | None, typer.Option("--truth-topic", help="Bag: ground-truth nav_msgs/Odometry topic [default: /base_pose_ground_truth].")] = None,
    no_truth: Annotated[bool, typer.Option("--no-truth", help="Bag: the recording has no ground truth (truth becomes NaN).")] = False,
    use_tf: Annotated[bool, typer.Option("--use-tf", help="Bag: odometry from the odom -> base_link transforms on /tf.")] = False,
    pairing: Annotated[Pairing, typer.Option("--pairing", help="Bag: poses at scan stamps by interpolation or the latest before.")] = Pairing.interpolate,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace a run already stored in --out.")] = False,
) -> None:
    """Import a ROS bag or a CARMEN log as a run folder, so recordings (also of real robots) can be evaluated."""
    from slamtrials.io.runfolder import RUN_FILE, write_run

    if no_truth and truth_topic is not None:
        raise ConfigError("give either --truth-topic or --no-truth, not both")
    if (out / RUN_FILE).exists() and not overwrite:
        raise ConfigError(f"{out}: already holds a run; choose another --out or pass --overwrite")
    kind = _import_format(source, fmt)
    if kind is ImportFormat.bag:
        from slamtrials.io.rosbag import ODOM_TOPIC, SCAN_TOPIC, TRUTH_TOPIC, run_from_bag

        record = run_from_bag(
            source,
            scan_topic=scan_topic or SCAN_TOPIC,
            odom_topic=odom_topic or ODOM_TOPIC,
            truth_topic=None if no_truth else (truth_topic or TRUTH_TOPIC),
            use_tf=use_tf,
            pairing=pairing.value,
        )
    else:
        bag_options = {"--scan-topic": scan_topic, "--odom-topic": odom_topic, "--truth-topic": truth_topic,
                       "--no-truth": no_truth or None, "--use-tf": use_tf or None}
        given = [name for name, value in bag_options.items() if value is not None]
        if given:
            raise ConfigError(f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} to ROS bags, not to CARMEN logs")
        record = _read_carmen_file(source)
    record.metadata.setdefault("imported_from", str(source))
    write_run(out, record)
    duration = float(record.t[-1] - record.t[0]) if len(record) else 0.0
    truth = "with ground truth" if record.metadata.get("truth_available", True) else "WITHOUT ground truth (NaN)"
    if kind is ImportFormat.carmen:
        truth = "truth = the log's first pose triple"
    make_console().print(f"{out}: {len(record)} frames x {record.scans.shape[1]} beams, {duration:.1f} s, {truth}")


def register(app: typer.Typer) -> None:
    """Add the ``export`` and ``import`` commands to ``app``."""
    app.command("export")(export_run)
    app.command("import")(import_run)
