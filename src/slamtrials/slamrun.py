"""Running a SLAM algorithm over a recorded run: the library behind ``slamtrials slam``.

:func:`load_recording` reads a run folder, a CARMEN log or a ROS bag as a
:class:`~slamtrials.record.RunRecord`; :func:`run_slam` feeds its frames to an algorithm of the
registry (:mod:`slamtrials.slam`) and times every call; :func:`write_slam_outputs` writes the results:

``trajectory.tum``
    the estimate, one pose per frame (TUM: ``t x y z qx qy qz qw``, map frame).
``trajectory.clf``
    a CARMEN log of the run whose FIRST pose triple is the SLAM estimate and SECOND the recorded
    odometry (ROBOTLASER1 lines, with the scans): the run as a corrected log, which ``slamtrials
    evaluate --estimate trajectory.clf --relations ...`` evaluates (its first triple).
``trajectory.log``
    the estimate as the Freiburg metricEvaluator's test logs hold one (``FLASER 0`` lines, the estimate in
    both triples: that program reads the second), for the original tool and for ``slamtrials evaluate``.
``map.yaml``, ``map.pgm``, ``map.png``
    the final map in ROS map_server form and as a picture.
``timing.csv``
    ``frame,t,seconds``: wall-clock seconds of each ``process`` call.
``slam.json``
    algorithm, preset, resolved config, seed, input, totals, and ``cost`` (CPU time and peak memory of
    the algorithm and of the run, time per update: :class:`~slamtrials.cost.RunCost`, not reproducible);
    written last, so it marks complete outputs.

This module composes io and slam, like the CLI does; it does not print.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from slamtrials.atomicfile import atomic_write_text
from slamtrials.cost import COST_KEY
from slamtrials.errors import ConfigError, FormatError
from slamtrials.external import ProgramRun
from slamtrials.record import OccupancyGrid, RunRecord, Trajectory
from slamtrials.slam.offline import SlamRun, run_over_recording

__all__ = [
    "SlamResult",
    "run_slam",
    "write_slam_outputs",
    "write_estimate_files",
    "write_program_outputs",
    "PROGRAM_OUTPUT_FILES",
    "load_recording",
    "OUTPUT_FILES",
    "SLAM_FILE",
]

SLAM_FILE = "slam.json"
#: Files :func:`write_slam_outputs` writes, in order (``slam.json`` last).
OUTPUT_FILES = (
    "trajectory.tum",
    "trajectory.clf",
    "trajectory.log",
    "map.yaml",
    "map.pgm",
    "map.png",
    "timing.csv",
    SLAM_FILE,
)


@dataclass(frozen=True, eq=False)
class SlamResult(SlamRun):
    """What one SLAM run over a recording produced: the :class:`~slamtrials.slam.offline.SlamRun` and
    the recording it ran over.

    Attributes
    ----------
    record:
        The recording that was processed.
    source:
        Where the recording came from (for ``slam.json``).
    """

    record: RunRecord
    source: str = ""


def run_slam(
    record: RunRecord,
    algorithm_name: str,
    *,
    preset: str | None = None,
    overrides: dict[str, Any] | None = None,
    seed: int = 0,
    on_frame: Callable[[int, int], None] | None = None,
    source: str = "",
) -> SlamResult:
    """Process every frame of ``record`` with algorithm ``algorithm_name``
    (:func:`slamtrials.slam.offline.run_over_recording`).

    Parameters
    ----------
    record:
        The recording.
    algorithm_name:
        Registry or entry-point name.
    preset, overrides:
        Configuration (see :func:`slamtrials.slam.resolve_config`).
    seed:
        The run's seed, used as a trial uses it (:mod:`slamtrials.seeding`): on a trial's run folder,
        the trial's seed gives the trial's own estimate.
    on_frame:
        Called as ``on_frame(index, total)`` after each frame (for progress bars).
    source:
        Where the record came from, kept for ``slam.json``.

    Raises
    ------
    ConfigError
        Unknown algorithm, preset or parameter, a bad value, a negative seed or an empty record.
    """
    run = run_over_recording(record, algorithm_name, preset=preset, overrides=overrides, seed=seed, on_frame=on_frame)
    return SlamResult(
        algorithm=algorithm_name,
        preset=preset,
        config=run.config,
        seed=run.seed,
        trajectory=run.trajectory,
        online=run.online,
        occupancy=run.occupancy,
        timing=run.timing,
        updates=run.updates,
        cost=run.cost,
        record=record,
        source=source,
    )


def write_estimate_files(
    out: Path, record: RunRecord, trajectory: Trajectory, estimate: np.ndarray, occupancy: OccupancyGrid
) -> list[Path]:
    """Write ``trajectory.tum`` (``trajectory``), ``trajectory.clf`` and ``trajectory.log`` (``estimate``,
    float64 ``[T, 3]``, one pose per frame of ``record``) and ``map.yaml``/``.pgm``/``.png`` into ``out``."""
    from slamtrials.io.carmen import carmen_from_run, carmen_from_trajectory, write_carmen
    from slamtrials.io.mapfile import write_map, write_map_png
    from slamtrials.io.tum import write_tum

    written = [write_tum(out / "trajectory.tum", trajectory)]
    clf = carmen_from_run(record, first_triple=estimate)  # first triple = the estimate; no ground truth
    written.append(write_carmen(out / "trajectory.clf", clf))
    written.append(write_carmen(out / "trajectory.log", carmen_from_trajectory(Trajectory(t=record.t, poses=estimate))))
    written.append(write_map(out / "map.yaml", occupancy.grid, occupancy.resolution, occupancy.origin))
    written.append(out / "map.pgm")
    written.append(write_map_png(out / "map.png", occupancy.grid))
    return [Path(p) for p in written]


def write_slam_outputs(result: SlamResult, out_dir: str | Path, *, overwrite: bool = False) -> list[Path]:
    """Write :data:`OUTPUT_FILES` into ``out_dir`` (created if needed); return the paths written.

    Raises
    ------
    ConfigError
        ``out_dir`` already holds SLAM outputs (``slam.json``) and ``overwrite`` is False.
    """
    out = Path(out_dir)
    if (out / SLAM_FILE).exists() and not overwrite:
        raise ConfigError(f"{out}: already holds SLAM outputs; choose another --out or pass --overwrite")
    out.mkdir(parents=True, exist_ok=True)
    estimate = result.estimate_per_frame(result.record)
    written = write_estimate_files(out, result.record, result.trajectory, estimate, result.occupancy)
    grid = result.occupancy
    rows = "".join(
        f"{k},{t!r},{s!r}\n" for k, (t, s) in enumerate(zip(result.record.t.tolist(), result.timing.tolist()))
    )
    written.append(atomic_write_text(out / "timing.csv", "frame,t,seconds\n" + rows))
    total = float(result.timing.sum())
    summary = {
        "algorithm": result.algorithm,
        "preset": result.preset,
        "config": result.config.model_dump(mode="json"),
        "seed": result.seed,
        "input": result.source,
        "frames": len(result.record),
        "updates": result.updates,
        "seconds_total": total,
        "ms_per_frame_mean": 1000.0 * total / max(len(result.record), 1),
        "ms_per_frame_max": 1000.0 * float(result.timing.max()) if len(result.timing) else math.nan,
        "map": {
            "shape": list(grid.grid.shape),
            "resolution": grid.resolution,
            "origin": [float(v) for v in grid.origin],
        },
        **({COST_KEY: result.cost.to_dict()} if result.cost is not None else {}),
        "trajectory_clf": "first pose triple = SLAM estimate, second = recorded odometry",
        "trajectory_log": "FLASER 0 lines, SLAM estimate in both pose triples (the Freiburg metricEvaluator's input)",
    }
    atomic_write_text(out / SLAM_FILE, json.dumps(summary, indent=2) + "\n")
    written.append(out / SLAM_FILE)
    return [Path(p) for p in written]


def load_recording(path: str | Path) -> RunRecord:
    """Read a run folder, a CARMEN log (``.clf``, ``.log``, ``.carmen``, optionally ``.gz``, ``.bz2``) or a ROS bag.

    A bag without the ground-truth topic is read without ground truth (NaN), which SLAM does not need.

    Raises
    ------
    FormatError
        The path does not exist or the file does not parse.
    """
    from slamtrials.io.runfolder import RunFolder, read_run
    from slamtrials.io.transfer import detect_recording_format, read_carmen_run

    path = Path(path)
    if not path.exists():
        raise FormatError(path, "no such file or folder")
    if path.is_dir() and RunFolder(path).is_complete():
        return read_run(path)
    if detect_recording_format(path) == "carmen":
        return read_carmen_run(path)
    from slamtrials.io.rosbag import TRUTH_TOPIC, bag_topics, run_from_bag

    truth = TRUTH_TOPIC if TRUTH_TOPIC in bag_topics(path) else None
    return run_from_bag(path, truth_topic=truth)


#: Files :func:`write_program_outputs` writes, in order (``slam.json`` last).
PROGRAM_OUTPUT_FILES = (
    "trajectory.tum",
    "trajectory.clf",
    "trajectory.log",
    "map.yaml",
    "map.pgm",
    "map.png",
    "program.tum",
    "program_stderr.txt",
    "slam.json",
)


def write_program_outputs(
    run: ProgramRun, record: RunRecord, out_dir: str | Path, *, source: str = "", overwrite: bool = False
) -> list[Path]:
    """Write :data:`PROGRAM_OUTPUT_FILES` into ``out_dir`` (created if needed); return the paths written.

    ``trajectory.tum``, ``.clf``, ``.log`` and the map are those of ``slamtrials slam``
    (:func:`slamtrials.slamrun.write_estimate_files`), with one pose per frame; ``program.tum`` holds
    the poses the program wrote, in the run's time base; ``program_stderr.txt`` the last lines of its
    stderr; ``slam.json`` the program, the command, the seed, the time origin, the pose counts and the
    program's ``cost`` (its process's CPU time and peak memory).

    Raises
    ------
    ConfigError
        ``out_dir`` already holds SLAM outputs and ``overwrite`` is False.
    """
    from slamtrials.io.tum import write_tum

    out = Path(out_dir)
    if (out / SLAM_FILE).exists() and not overwrite:
        raise ConfigError(f"{out}: already holds SLAM outputs; choose another --out or pass --overwrite")
    out.mkdir(parents=True, exist_ok=True)
    per_frame = Trajectory(t=np.asarray(record.t, dtype=np.float64), poses=run.estimate)
    written = write_estimate_files(out, record, per_frame, run.estimate, run.occupancy)
    written.append(write_tum(out / "program.tum", run.trajectory))
    written.append(atomic_write_text(out / "program_stderr.txt", "".join(f"{line}\n" for line in run.stderr_tail)))
    a = run.alignment
    summary = {
        "algorithm": run.spec.label,
        "program": run.spec.model_dump(mode="json"),
        "command": run.command,
        "seed": run.seed,
        "input": source,
        "frames": len(record),
        "seconds_total": run.seconds,
        "time_origin_s": run.time_origin_s,
        "poses_written": a.poses_read,
        "frames_at_a_pose": a.frames_at_pose,
        "frames_carried_by_odometry": a.frames_carried,
        "map": {
            "shape": list(run.occupancy.grid.shape),
            "resolution": run.occupancy.resolution,
            "origin": [float(v) for v in run.occupancy.origin],
            "drawn": "the scans at the estimated poses",
        },
        **({COST_KEY: run.cost.to_dict()} if run.cost is not None else {}),
        "trajectory_clf": "first pose triple = the estimate at each frame, second = recorded odometry",
    }
    written.append(atomic_write_text(out / SLAM_FILE, json.dumps(summary, indent=2) + "\n"))
    return [Path(p) for p in written]
