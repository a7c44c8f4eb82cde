"""The run folder of DESIGN.md: ``frames.npz`` (the recorded data) and ``run.json`` (what produced it).

``frames.npz`` holds ``t`` float64 [T] (s), ``scans`` float32 [T, B] (m), ``odometry`` float64 [T, 3]
(odometry frame), ``truth`` float64 [T, 3] (world frame) and ``stalled`` bool [T], and, for a run with a
SLAM estimate, ``estimate`` float64 [T, 3] (map frame; the algorithm's final trajectory), also written
as ``estimate.tum``, and ``online`` float64 [T, 3] (what the algorithm returned at each frame) when known.
``run.json`` holds the laser geometry, the run's metadata (world, seed, drawn odometry bias, outcome,
timings, resolved config) and the versions that produced it.
A run with a final SLAM map also has ``map.yaml`` + ``map.pgm`` (ROS map_server) and ``map.png``.
A replayed run refers to its source run's frames instead of copying them: its ``frames.npz`` holds
``t`` and the estimates, and ``run.json`` names the source (``frames_from``).

Every file is written atomically and ``run.json`` is written last, so a folder with a ``run.json`` is a
complete run; a crash mid-write leaves a folder that :func:`read_run` rejects rather than misreads.
"""

from __future__ import annotations

import io
import json
import os
import platform
import zipfile
import zlib
from pathlib import Path
from typing import Any

import numba
import numpy as np

from slamtrials.__about__ import __version__, source_revision
from slamtrials.atomicfile import atomic_write, atomic_write_text
from slamtrials.errors import FormatError
from slamtrials.io.layout import RunFolder
from slamtrials.io.mapfile import read_map, write_map, write_map_png
from slamtrials.io.tum import write_tum
from slamtrials.record import LaserGeometry, RunRecord, Trajectory

__all__ = ["write_run", "read_run", "RunFolder", "RUN_FORMAT", "RUN_FORMATS_READ", "FRAMES_FROM"]

#: ``run.json`` key of a replayed run: where its recorded frames are (``{"path": relative, "absolute": ...}``).
FRAMES_FROM = "frames_from"

#: Format tag of run.json as written now. Version 2 (this one): the trial config's ``explore`` section
#: holds no robot fields (they are ``sim.robot``'s) and ``campaign.metric`` the whole sampling rule.
RUN_FORMAT = "slamtrials-run/2"
#: Format tags :func:`read_run` reads: version 1 run folders have the same files and keys.
RUN_FORMATS_READ = ("slamtrials-run/1", RUN_FORMAT)

_ARRAYS: dict[str, tuple[type, int | None]] = {  # name -> (dtype, size of the last axis or None)
    "t": (np.float64, None),
    "scans": (np.float32, None),
    "odometry": (np.float64, 3),
    "truth": (np.float64, 3),
    "stalled": (np.bool_, None),
}
#: Optional pose arrays, float64 [T, 3] (map frame): the final and the online SLAM estimate.
_ESTIMATES = ("estimate", "online")
_LASER_KEYS = ("angle_min", "angle_increment", "range_min", "range_max")


def _revision() -> dict[str, str]:
    """``{"source": commit}`` when running from a git checkout (see :func:`source_revision`), else empty."""
    revision = source_revision()
    return {"source": revision} if revision else {}


def json_default(value: Any) -> Any:
    """``json.dumps(default=...)`` hook: numpy arrays and scalars, and paths, as plain JSON values."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot store {type(value).__name__} as JSON")


def write_run(folder: str | Path, record: RunRecord, *, frames_from: str | Path | None = None) -> Path:
    """Write ``record`` as a run folder (created if needed) and return the folder's path.

    ``frames.npz`` is compressed; ``run.json`` is written last and marks the run complete. An existing
    run in ``folder`` is replaced file by file, each replacement atomic.

    ``frames_from``: the run folder that already holds ``record``'s recorded frames (a replay's source
    run). ``frames.npz`` then holds only ``t`` and the estimates, and ``run.json`` names that folder
    (relative to this one, and absolute) under :data:`FRAMES_FROM`; :func:`read_run` reads the frames
    from there. The source must hold the same times as ``record``.
    """
    files = RunFolder(folder)
    folder = files.path
    folder.mkdir(parents=True, exist_ok=True)
    files.run_json.unlink(missing_ok=True)  # the folder is incomplete until run.json is back
    arrays = {name: np.asarray(getattr(record, name), dtype=dtype) for name, (dtype, _) in _ARRAYS.items()}
    reference = None
    if frames_from is not None:
        source = Path(frames_from).absolute()
        reference = {"path": os.path.relpath(source, folder.absolute()), "absolute": str(source)}
        arrays = {"t": arrays["t"]}
    if record.estimate is not None:
        arrays["estimate"] = np.asarray(record.estimate, dtype=np.float64).reshape(len(record), 3)
        write_tum(files.estimate, Trajectory(t=arrays["t"], poses=arrays["estimate"]))
    else:
        files.estimate.unlink(missing_ok=True)
    if record.online is not None:
        arrays["online"] = np.asarray(record.online, dtype=np.float64).reshape(len(record), 3)
    if record.map is not None:
        write_map(files.map, record.map.grid, record.map.resolution, record.map.origin)
        write_map_png(files.map_picture, record.map.grid)
    else:
        for stale in files.map_files:
            stale.unlink(missing_ok=True)
    atomic_write(files.frames, lambda handle: np.savez_compressed(handle, **arrays))
    doc = {
        "format": RUN_FORMAT,
        "versions": {
            "slamtrials": __version__,
            **_revision(),
            "python": platform.python_version(),
            "numpy": np.__version__,
            "numba": numba.__version__,
            "libc": " ".join(platform.libc_ver()),
            "machine": platform.machine(),
        },
        "frames": len(record),
        "beams": int(record.scans.shape[1]) if record.scans.ndim == 2 else 0,
        "laser": record.laser.to_dict(),
        **{k: v for k, v in record.metadata.items() if k != FRAMES_FROM},
    }
    if reference is not None:
        doc[FRAMES_FROM] = reference
    atomic_write_text(files.run_json, json.dumps(doc, indent=2, default=json_default) + "\n")
    return folder


def _read_run_json(path: Path) -> dict[str, Any]:
    if not path.is_file():
        raise FormatError(path, "missing: not a complete run folder (run.json is written last)")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"not valid JSON: {exc.msg}", line=exc.lineno) from None
    except UnicodeDecodeError:
        raise FormatError(path, "not UTF-8 text") from None
    if not isinstance(doc, dict) or doc.get("format") not in RUN_FORMATS_READ:
        found = doc.get("format") if isinstance(doc, dict) else None
        raise FormatError(
            path, f'expected a JSON object with "format" one of {", ".join(RUN_FORMATS_READ)}, got {found!r}'
        )
    laser = doc.get("laser")
    if not isinstance(laser, dict) or any(not isinstance(laser.get(k), (int, float)) for k in _LASER_KEYS):
        raise FormatError(path, f"field 'laser' must be an object with numbers {', '.join(_LASER_KEYS)}")
    return doc


def _load_npz(path: Path) -> dict[str, np.ndarray]:
    if not path.is_file():
        raise FormatError(path, "missing: every run folder has frames.npz")
    try:
        with np.load(path, allow_pickle=False) as npz:
            return {name: npz[name] for name in npz.files if name in _ARRAYS or name in _ESTIMATES}
    except (zipfile.BadZipFile, zlib.error, ValueError, OSError, EOFError, io.UnsupportedOperation) as exc:
        raise FormatError(path, f"not a readable .npz archive ({exc})") from None


def _source_folder(files: RunFolder, reference: Any) -> Path:
    """The folder a replay's ``frames_from`` names: relative to the run folder, else the absolute path."""
    if not isinstance(reference, dict) or not isinstance(reference.get("path"), str):
        raise FormatError(files.run_json, f"field '{FRAMES_FROM}' must be an object with a 'path'")
    for candidate in (files.path / reference["path"], Path(str(reference.get("absolute", "")))):
        if str(candidate) and RunFolder(candidate).is_complete():
            return candidate.resolve()
    raise FormatError(
        files.run_json,
        f"its recorded frames are those of the run {reference.get('absolute') or reference['path']}, which is not "
        "there any more (moved or deleted?): a replayed run needs its source campaign beside it",
    )


def _recorded_frames(files: RunFolder, doc: dict[str, Any], depth: int = 0) -> dict[str, np.ndarray]:
    """The recorded arrays of a run folder: its own ``frames.npz``, or its source's for a replayed run."""
    arrays = _load_npz(files.frames)
    reference = doc.get(FRAMES_FROM)
    if reference is None:
        return _checked_frames(files.frames, arrays)
    if depth > 16:
        raise FormatError(files.run_json, f"'{FRAMES_FROM}' references go on for more than 16 runs")
    source = RunFolder(_source_folder(files, reference))
    recorded = _recorded_frames(source, _read_run_json(source.run_json), depth + 1)
    if "t" not in arrays or not np.array_equal(arrays["t"], recorded["t"]):
        raise FormatError(
            files.frames,
            f"its times are not those of its source run {source.path}: the source changed since the replay",
        )
    recorded = {k: v for k, v in recorded.items() if k not in _ESTIMATES}
    for name in _ESTIMATES:
        if name in arrays:
            recorded[name] = arrays[name]
    return _checked_frames(files.frames, recorded)


def _checked_frames(path: Path, arrays: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    for name, (dtype, last) in _ARRAYS.items():
        if name not in arrays:
            raise FormatError(path, f"array '{name}' is missing")
        if arrays[name].dtype != dtype:
            raise FormatError(path, f"array '{name}' has dtype {arrays[name].dtype}, expected {np.dtype(dtype)}")
        if last is not None and (arrays[name].ndim != 2 or arrays[name].shape[1] != last):
            raise FormatError(path, f"array '{name}' has shape {arrays[name].shape}, expected [T, {last}]")
    n = len(arrays["t"])
    for name in _ESTIMATES:
        if name in arrays and (arrays[name].dtype != np.float64 or arrays[name].shape != (n, 3)):
            raise FormatError(
                path, f"array '{name}' has {arrays[name].dtype} {arrays[name].shape}, expected float64 [{n}, 3]"
            )
    if arrays["scans"].ndim != 2 or any(len(a) != n for a in arrays.values()):
        raise FormatError(path, f"arrays disagree on the number of frames: { {k: v.shape for k, v in arrays.items()} }")
    if n > 1 and not np.all(np.diff(arrays["t"]) > 0):
        raise FormatError(path, "timestamps 't' are not strictly increasing")
    return arrays


def read_run(folder: str | Path) -> RunRecord:
    """Read a run folder written by :func:`write_run`.

    Raises
    ------
    FormatError
        A file is missing, unreadable, or its arrays have the wrong names, dtypes or shapes.
    """
    files = RunFolder(folder)
    folder = files.path
    if not folder.is_dir():
        raise FormatError(folder, "not a run folder (no such directory)")
    doc = _read_run_json(files.run_json)
    arrays = _recorded_frames(files, doc)
    if arrays["scans"].shape[1] != doc.get("beams", arrays["scans"].shape[1]):
        raise FormatError(files.run_json, f"says {doc['beams']} beams but frames.npz has {arrays['scans'].shape[1]}")
    try:
        laser = LaserGeometry.from_dict(doc.pop("laser"))
    except ValueError as exc:
        raise FormatError(files.run_json, f"field 'laser': {exc}") from None
    metadata = {k: v for k, v in doc.items() if k not in ("format", "frames", "beams", FRAMES_FROM)}
    slam_map = read_map(files.map) if files.map.is_file() else None
    return RunRecord(**arrays, laser=laser, metadata=metadata, map=slam_map)
