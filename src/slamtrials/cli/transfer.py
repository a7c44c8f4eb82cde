"""``slamtrials export`` and ``slamtrials import``: a run folder to and from ROS bags, CARMEN logs and TUM files."""

from __future__ import annotations

from enum import Enum
from pathlib import Path
from typing import Annotated

import typer

from slamtrials.cli.common import make_console
from slamtrials.errors import ConfigError


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


def export_run(
    run: Annotated[Path, typer.Argument(metavar="RUN", help="Run folder (frames.npz + run.json).")],
    to: Annotated[
        ExportFormat,
        typer.Option(
            "--to",
            "-t",
            help="bag: ROS 1 .bag; bag2: ROS 2 bag folder (MCAP); carmen: CARMEN log; tum: TUM trajectory.",
        ),
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="File (or ROS 2 bag folder) to write.")],
    what: Annotated[
        TumSource | None, typer.Option("--what", help="For --to tum: the ground truth (default) or the odometry.")
    ] = None,
    time_origin: Annotated[
        int | None, typer.Option("--time-origin-ns", help="For bags: ROS stamp (ns) of t = 0; default 1 s.")
    ] = None,
    compress: Annotated[
        bool, typer.Option("--compress", help="For bags: LZ4 chunks (ROS 1) or zstd MCAP chunks (ROS 2).")
    ] = False,
    carmen_kind: Annotated[
        str, typer.Option("--carmen-kind", help="For --to carmen: ROBOTLASER1 (geometry on every line) or FLASER.")
    ] = "ROBOTLASER1",
    truth: Annotated[
        bool,
        typer.Option(
            "--truth/--no-truth",
            help="For carmen and bags: also write the ground truth (TRUEPOS lines; /base_pose_ground_truth and the "
            "run's start pose, errors and scores in a bag's /slamtrials/run), so that import gives the run back. "
            "Default: none, what a SLAM program may be given.",
        ),
    ] = False,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace an existing --out.")] = False,
) -> None:
    """Export a run's laser, odometry and ground truth as a ROS bag (Stage topics), a CARMEN log or a TUM file.

    A CARMEN log's laser lines hold the laser's pose by odometry (first pose triple) and the odometry of
    the base (second). The ground truth is written only with --truth: into TRUEPOS lines, or a bag's
    ground-truth topic. Never give a program a log or bag exported with --truth.
    """
    from slamtrials.io.runfolder import read_run
    from slamtrials.io.transfer import export_record

    if what is not None and to is not ExportFormat.tum:
        raise ConfigError("--what applies to --to tum only")
    if (time_origin is not None or compress) and to not in (ExportFormat.bag, ExportFormat.bag2):
        raise ConfigError("--time-origin-ns and --compress apply to --to bag and --to bag2 only")
    if truth and to is ExportFormat.tum:
        raise ConfigError("--truth applies to --to carmen, bag and bag2 (a TUM file holds one trajectory: --what)")
    if out.exists() and not overwrite:
        raise ConfigError(f"{out}: already exists; choose another --out or pass --overwrite")
    record = read_run(run)
    try:
        summary = export_record(
            record,
            out,
            to.value,
            tum_source=(what or TumSource.truth).value,
            time_origin_ns=time_origin,
            compress=compress,
            carmen_kind=carmen_kind,
            truth=truth,
            overwrite=overwrite,
        )
    except ConfigError as exc:
        raise ConfigError(f"{run}: {exc}") from None
    make_console().print(summary)


def import_run(
    source: Annotated[
        Path,
        typer.Argument(
            metavar="FILE", help="ROS 1 .bag, ROS 2 bag folder or .mcap, or CARMEN log (.clf, .log, .gz, .bz2)."
        ),
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="Run folder to write (frames.npz, run.json).")],
    fmt: Annotated[
        ImportFormat, typer.Option("--format", "-f", help="Input format; auto: from the name and first bytes.")
    ] = ImportFormat.auto,
    scan_topic: Annotated[
        str | None, typer.Option("--scan-topic", help="Bag: sensor_msgs/LaserScan topic \\[default: /base_scan].")
    ] = None,
    odom_topic: Annotated[
        str | None, typer.Option("--odom-topic", help="Bag: nav_msgs/Odometry topic \\[default: /odom].")
    ] = None,
    truth_topic: Annotated[
        str | None,
        typer.Option(
            "--truth-topic",
            help="Bag: ground-truth nav_msgs/Odometry topic \\[default: /base_pose_ground_truth when the bag has it, "
            "else no ground truth].",
        ),
    ] = None,
    no_truth: Annotated[
        bool,
        typer.Option(
            "--no-truth",
            help="The recording has no ground truth: truth becomes NaN (bag: no ground-truth topic; CARMEN: "
            "TRUEPOS lines ignored and the first pose triple not taken for truth).",
        ),
    ] = False,
    use_tf: Annotated[
        bool, typer.Option("--use-tf", help="Bag: odometry from the odom -> base_link transforms on /tf.")
    ] = False,
    pairing: Annotated[
        Pairing, typer.Option("--pairing", help="Bag: poses at scan stamps by interpolation or the latest before.")
    ] = Pairing.interpolate,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace a run already stored in --out.")] = False,
) -> None:
    """Import a ROS bag or a CARMEN log as a run folder, so recordings (also of real robots) can be evaluated.

    A CARMEN log's ground truth comes from its TRUEPOS lines; a log without them (a real robot's) gets its
    laser lines' first pose triple as truth, which is no ground truth (run.json's truth_source says so).
    """
    from slamtrials.io.runfolder import RunFolder, write_run
    from slamtrials.io.transfer import detect_recording_format, read_carmen_run

    if no_truth and truth_topic is not None:
        raise ConfigError("give either --truth-topic or --no-truth, not both")
    if RunFolder(out).is_complete() and not overwrite:
        raise ConfigError(f"{out}: already holds a run; choose another --out or pass --overwrite")
    kind = ImportFormat(detect_recording_format(source)) if fmt is ImportFormat.auto else fmt
    if kind is ImportFormat.bag:
        from slamtrials.io.rosbag import ODOM_TOPIC, SCAN_TOPIC, TRUTH_TOPIC, bag_topics, run_from_bag

        if truth_topic is None and not no_truth:  # the default topic when the bag has it, else no truth
            truth_topic = TRUTH_TOPIC if TRUTH_TOPIC in bag_topics(source) else None
            no_truth = truth_topic is None
        record = run_from_bag(
            source,
            scan_topic=scan_topic or SCAN_TOPIC,
            odom_topic=odom_topic or ODOM_TOPIC,
            truth_topic=None if no_truth else truth_topic,
            use_tf=use_tf,
            pairing=pairing.value,
        )
    else:
        bag_options = {
            "--scan-topic": scan_topic,
            "--odom-topic": odom_topic,
            "--truth-topic": truth_topic,
            "--use-tf": use_tf or None,
        }
        given = [name for name, value in bag_options.items() if value is not None]
        if given:
            raise ConfigError(
                f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} to ROS bags, not to CARMEN logs"
            )
        record = read_carmen_run(source, truth=not no_truth)
    record.metadata.setdefault("imported_from", str(source))
    write_run(out, record)
    duration = float(record.t[-1] - record.t[0]) if len(record) else 0.0
    truth = "with ground truth" if record.metadata.get("truth_available", True) else "WITHOUT ground truth (NaN)"
    if kind is ImportFormat.carmen and "truth_available" not in record.metadata:
        truth = "truth = the log's first pose triple (no TRUEPOS lines: not ground truth)"
    elif kind is ImportFormat.carmen and record.metadata["truth_available"]:
        truth = "with ground truth (TRUEPOS lines)"
    make_console().print(f"{out}: {len(record)} frames x {record.scans.shape[1]} beams, {duration:.1f} s, {truth}")


def register(app: typer.Typer) -> None:
    """Add the ``export`` and ``import`` commands to ``app``."""
    app.command("export")(export_run)
    app.command("import")(import_run)
