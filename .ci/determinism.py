"""Proof that results do not depend on the CPU's SIMD: the same outputs with numpy and numba held to baseline code.

``check`` runs ``produce`` twice in fresh processes and compares what they wrote, file by file:

1. as the machine runs it (numpy's dispatched SIMD code, numba compiling for the host CPU);
2. with numpy's CPU dispatch held to its baseline (``NPY_DISABLE_CPU_FEATURES`` naming every dispatch
   target above the baseline that this CPU has, e.g. ``X86_V3 X86_V4 AVX512_ICL`` on an AVX-512 machine
   with numpy 2.4, ``AVX AVX2 FMA3 F16C AVX512F AVX512_SKX ...`` with older numpy) and numba compiling
   for a generic x86-64 CPU (``NUMBA_CPU_NAME=generic``, with its own ``NUMBA_CACHE_DIR`` so that no
   machine code cached for the host is reused).

``produce OUT`` writes into OUT: the bundled catalog regenerated (``catalog/``), a generated world that
is not in the catalog (``generated/``), an exploration trial on office_small_01 (``trial/``: the run
folder and its sampled relations and errors) with the ``paper`` error profile (named: the noise-free
laser and the per-run bias alone), the same trial with ``realistic``, the default profile of every
command (``trial_realistic/``: laser noise, short readings, dropouts and odometry noise drawn, and the
explorer's handling of noisy scans); both name their profile, so a change of the default changes neither, and GMapping and karto over the first scans of the MIT CSAIL
CARMEN log (``gmapping/``, ``karto/``), and ``calibrate`` and ``validate`` (``realistic`` profile, one
replica) over the first scans of that log (``calibration/``, ``validation/``); the log's parts only when
the shared data is there: ``SLAMTRIALS_SHARED`` or ``../shared`` beside the repository. It then writes
``manifest.json``: the sha256 of every file, and of every array of an ``.npz`` file (a zip, whose bytes
depend on the zlib that compressed it); JSON files are hashed without their wall-clock timings, software
versions and ``cost`` objects (CPU time and memory of a run: measurements, not results); ``timing.csv``
is left out.

``check`` fails (exit status 1) naming every file that differs between the two passes, or a regenerated
catalog file that differs from the one bundled in the package. Usage::

    python .ci/determinism.py check [--work DIR] [--keep] [--flip FILE]
    python .ci/determinism.py produce OUT
    python .ci/determinism.py compare A/manifest.json B/manifest.json
    python .ci/determinism.py hash FOLDER        # print the manifest of any folder (run folders, ...)
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
MANIFEST = "manifest.json"
#: The trial: a bundled world and a seed (it explores office_small_01 in 172 s simulated, about 7 s on one
#: core once compiled; 194 s and about 9 s with the realistic profile), with a cap on simulated time (s)
#: that bounds the check's run time.
TRIAL_WORLD, TRIAL_SEED, TRIAL_MAX_TIME = "office_small_01", 1, 300.0
#: The error profiles of the trials, and the folder each one's run is written to.
TRIAL_PROFILES = (("paper", "trial"), ("realistic", "trial_realistic"))
#: A world generated from arguments that no catalog entry uses.
GENERATED = ("school", 400.0, 5)
#: GMapping over this many scans of the MIT CSAIL log, with this seed.
LOG_SCANS, LOG_SEED = 300, 1
#: The calibration (GMapping's reference, then the fit) over this many scans, with this many bootstrap
#: replicates, and the validation replicas of the same scans (the relations that fall in them).
CALIBRATION_SCANS, CALIBRATION_BOOTSTRAP, VALIDATION_RUNS = 600, 10, 1
#: Keys of JSON outputs that hold wall-clock measurements or software versions, not results.
_VOLATILE_WORDS = ("versions", "wall", "seconds", "realtime", "ms_per_frame")
#: Keys of JSON outputs whose whole value is a measurement of the machine: a run's cost (CPU time, memory).
_VOLATILE_KEYS = ("cost",)
#: Files that hold only wall-clock measurements.
_VOLATILE_FILES = {"timing.csv", MANIFEST}


# ----------------------------------------------------------------------------------------- hashing


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _without_volatile(value):
    """A JSON value without the keys that name wall-clock timings, versions or costs (at any depth)."""
    if isinstance(value, dict):
        return {
            k: _without_volatile(v)
            for k, v in value.items()
            if k not in _VOLATILE_KEYS and not any(w in k.lower() for w in _VOLATILE_WORDS)
        }
    if isinstance(value, list):
        return [_without_volatile(v) for v in value]
    return value


def _npz_entries(data: bytes) -> dict[str, str]:
    """sha256 of every array of an ``.npz`` (dtype, shape and bytes), by array name."""
    import numpy as np

    out = {}
    with np.load(io.BytesIO(data), allow_pickle=False) as arrays:
        for name in sorted(arrays.files):
            a = np.ascontiguousarray(arrays[name])
            out[name] = _sha256(f"{a.dtype.str}{a.shape}".encode() + a.tobytes())
    return out


def manifest_of(folder: Path) -> dict[str, str]:
    """``{relative path: sha256}`` of the files under ``folder``; ``path[array]`` for each array of an ``.npz``."""
    files: dict[str, str] = {}
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        rel = path.relative_to(folder).as_posix()
        if path.name in _VOLATILE_FILES:
            continue
        data = path.read_bytes()
        if path.suffix == ".npz":
            try:
                entries = _npz_entries(data)
            except (ValueError, OSError, zipfile.BadZipFile) as exc:
                files[rel] = f"unreadable npz: {exc}"
                continue
            files.update({f"{rel}[{name}]": digest for name, digest in entries.items()})
        elif path.suffix == ".json":
            try:
                doc = _without_volatile(json.loads(data))
            except ValueError:
                files[rel] = _sha256(data)
                continue
            files[rel] = _sha256(json.dumps(doc, sort_keys=True).encode())
        else:
            files[rel] = _sha256(data)
    return files


def compare(a: dict[str, str], b: dict[str, str], label_a: str, label_b: str) -> list[str]:
    """One line per file that differs, or is in one manifest only."""
    lines = []
    for name in sorted(set(a) | set(b)):
        if name not in b:
            lines.append(f"{name}: only in {label_a}")
        elif name not in a:
            lines.append(f"{name}: only in {label_b}")
        elif a[name] != b[name]:
            lines.append(f"{name}: differs ({label_a} {a[name][:12]}, {label_b} {b[name][:12]})")
    return lines


# ----------------------------------------------------------------------------------------- the outputs


def shared_data() -> Path:
    """The shared data folder the tests use: ``SLAMTRIALS_SHARED`` or ``shared`` beside the repository."""
    return Path(os.environ.get("SLAMTRIALS_SHARED", REPO.parent / "shared"))


def _environment() -> dict:
    """What this process runs with: numpy's dispatch targets in use, numba's CPU (not compared)."""
    import numba
    import numpy as np

    features, dispatch = numpy_dispatch()
    return {
        "numpy": np.__version__,
        "numba": numba.__version__,
        "numpy_dispatch_in_use": [f for f in dispatch if features.get(f)],
        "NPY_DISABLE_CPU_FEATURES": os.environ.get("NPY_DISABLE_CPU_FEATURES", ""),
        "numba_cpu_name": numba.config.CPU_NAME or "host",
        "NUMBA_CACHE_DIR": os.environ.get("NUMBA_CACHE_DIR", ""),
    }


def numpy_dispatch() -> tuple[dict[str, bool], list[str]]:
    """numpy's CPU features as detected (after any NPY_DISABLE_CPU_FEATURES) and its dispatch targets."""
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    except ImportError:  # numpy 1.x
        from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    return dict(__cpu_features__), list(__cpu_dispatch__)


def produce(out: Path) -> dict:
    """Write every output into ``out`` and return the manifest (also written to ``out/manifest.json``)."""
    out.mkdir(parents=True, exist_ok=True)
    notes: list[str] = []
    timings: dict[str, float] = {}

    started = time.perf_counter()
    from slamtrials.worlds.catalog_build import build_catalog

    (out / "catalog").mkdir()
    build_catalog(out / "catalog")
    timings["catalog"] = time.perf_counter() - started

    started = time.perf_counter()
    from slamtrials.worlds.formats.rosmap_save import save_rosmap
    from slamtrials.worlds.generate import generate_world

    kind, area, seed = GENERATED
    world = generate_world(kind, area, seed=seed)
    (out / "generated").mkdir()
    save_rosmap(world, out / "generated" / f"{world.name}.yaml")
    timings["generated"] = time.perf_counter() - started

    from slamtrials.evaluation import evaluate_run
    from slamtrials.io.runfolder import write_run
    from slamtrials.trial import TrialConfig, run_trial
    from slamtrials.worlds import load_world

    for profile, folder in TRIAL_PROFILES:
        started = time.perf_counter()
        config = TrialConfig.from_dict({"sim": {"profile": profile}, "termination": {"max_time": TRIAL_MAX_TIME}})
        record = run_trial(load_world(TRIAL_WORLD), config, TRIAL_SEED)
        write_run(out / folder, record)
        evaluate_run(out / folder, seed=TRIAL_SEED)
        timings[folder] = time.perf_counter() - started

    log = shared_data() / "data" / "mit-csail" / "mit-csail.clf"
    if log.is_file():
        from dataclasses import replace

        from slamtrials.slamrun import load_recording, run_slam, write_slam_outputs

        full = load_recording(log)
        n = min(LOG_SCANS, len(full))
        part = replace(
            full,
            t=full.t[:n],
            scans=full.scans[:n],
            odometry=full.odometry[:n],
            truth=full.truth[:n],
            stalled=full.stalled[:n],
            estimate=None,
        )
        for algorithm in ("gmapping", "karto"):
            started = time.perf_counter()
            write_slam_outputs(run_slam(part, algorithm, seed=LOG_SEED, source=log.name), out / algorithm)
            timings[algorithm] = time.perf_counter() - started
        _calibrate_and_validate(full, log, out, timings)
    else:
        notes.append(f"no MIT CSAIL log at {log}: SLAM, calibrate and validate on a log not checked")

    manifest = {
        "files": manifest_of(out),
        "notes": notes,
        "environment": _environment(),
        "seconds": {k: round(v, 1) for k, v in timings.items()},
    }
    (out / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    return manifest


def _calibrate_and_validate(full, log: Path, out: Path, timings: dict[str, float]) -> None:
    """``calibrate`` and ``validate`` on the first :data:`CALIBRATION_SCANS` scans of the log ``full``: the
    fitted profile with its standard errors (``calibration/``) and the validation's numbers with the
    ``realistic`` profile (``validation/``), as JSON."""
    from dataclasses import replace

    from slamtrials.calibration import CalibrationSettings, calibrate, slam_reference
    from slamtrials.io.relations import read_relations
    from slamtrials.sim.profiles import BUNDLED_PROFILES
    from slamtrials.validation.validate import ValidationSettings, validate

    n = min(CALIBRATION_SCANS, len(full))
    part = replace(
        full,
        t=full.t[:n],
        scans=full.scans[:n],
        odometry=full.odometry[:n],
        truth=full.truth[:n],
        stalled=full.stalled[:n],
        estimate=None,
    )
    started = time.perf_counter()
    reference = slam_reference(part, "gmapping", seed=LOG_SEED)
    fit = calibrate(part, reference, CalibrationSettings(bootstrap=CALIBRATION_BOOTSTRAP), seed=LOG_SEED)
    doc = {
        "profile": fit.profile("determinism", "").model_dump(mode="json"),
        "fitted": [[value.name, value.value, value.stderr] for value in fit.fitted],
    }
    (out / "calibration").mkdir()
    (out / "calibration" / "profile.json").write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    timings["calibration"] = time.perf_counter() - started

    started = time.perf_counter()
    every = read_relations(log.with_suffix(".relations"))
    inside = (every.t1 <= part.t[-1]) & (every.t2 <= part.t[-1])
    relations = replace(every, t1=every.t1[inside], t2=every.t2[inside], delta=every.delta[inside])
    result = validate(
        part,
        relations,
        BUNDLED_PROFILES["realistic"],
        ValidationSettings(runs=VALIDATION_RUNS, reference_seed=LOG_SEED),
        log=log.name,
        relations_source=log.with_suffix(".relations").name,
    )
    (out / "validation").mkdir()
    (out / "validation" / "validation.json").write_text(json.dumps(result.to_dict(), indent=1) + "\n", encoding="utf-8")
    timings["validation"] = time.perf_counter() - started


# ----------------------------------------------------------------------------------------- two passes


def bundled_catalog() -> Path:
    """The data folder of the catalog bundled with the slamtrials that this Python imports."""
    import slamtrials.worlds

    return Path(slamtrials.worlds.__file__).resolve().parent / "data"


def baseline_environment(cache_dir: Path) -> dict[str, str]:
    """The environment of the second pass: numpy at its baseline code, numba for a generic CPU."""
    features, dispatch = numpy_dispatch()
    env = dict(os.environ)
    env.pop("NPY_ENABLE_CPU_FEATURES", None)
    present = [f for f in dispatch if features.get(f)]  # numpy refuses to disable what the CPU lacks
    if present:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(present)
    else:
        env.pop("NPY_DISABLE_CPU_FEATURES", None)
    env["NUMBA_CPU_NAME"] = "generic"
    env.pop("NUMBA_CPU_FEATURES", None)
    env["NUMBA_CACHE_DIR"] = str(cache_dir)
    return env


def _run_pass(label: str, out: Path, env: dict[str, str]) -> dict:
    print(f"determinism: pass '{label}' -> {out}", flush=True)
    started = time.perf_counter()
    result = subprocess.run([sys.executable, str(Path(__file__).resolve()), "produce", str(out)], env=env)
    if result.returncode != 0:
        raise SystemExit(f"determinism: pass '{label}' failed (exit status {result.returncode})")
    manifest = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    parts = ", ".join(f"{k} {v:.0f} s" for k, v in manifest["seconds"].items())
    env_info = manifest["environment"]
    print(
        f"determinism: pass '{label}': {len(manifest['files'])} files hashed in {time.perf_counter() - started:.0f} s "
        f"({parts}); numpy dispatch in use: {' '.join(env_info['numpy_dispatch_in_use']) or 'baseline only'}; "
        f"numba CPU: {env_info['numba_cpu_name']}",
        flush=True,
    )
    for note in manifest["notes"]:
        print(f"determinism: note: {note}", flush=True)
    return manifest


def flip_byte(path: Path) -> None:
    """Flip every bit of the middle byte of ``path`` (for showing that a difference is caught)."""
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))


def check(work: Path, flip: str | None = None) -> int:
    """Both passes, then the comparison; returns the exit status.

    ``flip`` (a path relative to a pass's folder) is a self-test: that file of the second pass gets one byte
    flipped before the comparison, which must then fail naming it.
    """
    normal_env = dict(os.environ)
    for name in ("NPY_DISABLE_CPU_FEATURES", "NPY_ENABLE_CPU_FEATURES", "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES"):
        normal_env.pop(name, None)
    baseline_env = baseline_environment(work / "numba-cache-generic")
    print(
        f"determinism: second pass with NPY_DISABLE_CPU_FEATURES='{baseline_env.get('NPY_DISABLE_CPU_FEATURES', '')}' "
        f"NUMBA_CPU_NAME=generic NUMBA_CACHE_DIR={baseline_env['NUMBA_CACHE_DIR']}",
        flush=True,
    )
    normal = _run_pass("as-is", work / "as-is", normal_env)
    baseline = _run_pass("baseline", work / "baseline", baseline_env)
    if flip is not None:
        if not (work / "baseline" / flip).is_file():
            raise SystemExit(f"determinism: --flip {flip}: no such file in {work / 'baseline'}")
        print(f"determinism: self-test: flipping one byte of baseline/{flip}", flush=True)
        flip_byte(work / "baseline" / flip)
        baseline["files"] = manifest_of(work / "baseline")

    problems = []
    if baseline["environment"]["numpy_dispatch_in_use"]:
        problems.append(
            f"numpy still dispatches to {baseline['environment']['numpy_dispatch_in_use']} in the baseline pass"
        )
    if baseline["environment"]["numba_cpu_name"] != "generic":
        problems.append("numba did not compile for a generic CPU in the baseline pass")
    problems += compare(normal["files"], baseline["files"], "as-is", "baseline")
    bundled = bundled_catalog()
    catalog = {k.removeprefix("catalog/"): v for k, v in normal["files"].items() if k.startswith("catalog/")}
    problems += [
        f"catalog/{line} (regenerated vs bundled in {bundled})"
        for line in compare(catalog, manifest_of(bundled), "regenerated", "bundled")
    ]
    if problems:
        for line in problems:
            print(f"determinism: FAIL {line}", flush=True)
        print(f"determinism: {len(problems)} problem(s); the outputs are in {work}", flush=True)
        return 1
    print(
        f"determinism: OK, {len(normal['files'])} files the same bit for bit in both passes, "
        "and the regenerated catalog equals the bundled one",
        flush=True,
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("check", help="produce twice (as is, and at baseline) and compare")
    p.add_argument("--work", type=Path, help="folder for both passes (default: a temporary one)")
    p.add_argument("--keep", action="store_true", help="keep the temporary folder")
    p.add_argument(
        "--flip", metavar="FILE", help="self-test: flip a byte of FILE (e.g. trial/map.pgm) in the second pass"
    )
    p = sub.add_parser("produce", help="write the outputs and their manifest into OUT")
    p.add_argument("out", type=Path)
    p = sub.add_parser("compare", help="compare two manifest.json files")
    p.add_argument("a", type=Path)
    p.add_argument("b", type=Path)
    p = sub.add_parser("hash", help="print the manifest of a folder")
    p.add_argument("folder", type=Path)
    args = parser.parse_args(argv)

    if args.command == "produce":
        produce(args.out)
        return 0
    if args.command == "hash":
        print(json.dumps(manifest_of(args.folder), indent=1))
        return 0
    if args.command == "compare":
        a, b = (json.loads(p.read_text(encoding="utf-8"))["files"] for p in (args.a, args.b))
        lines = compare(a, b, str(args.a), str(args.b))
        for line in lines:
            print(f"determinism: FAIL {line}")
        return 1 if lines else 0
    if args.work is not None:
        if args.work.exists() and any(args.work.iterdir()):
            raise SystemExit(f"determinism: {args.work} is not empty; give a new or empty folder")
        return check(args.work, args.flip)
    work = Path(tempfile.mkdtemp(prefix="slamtrials-determinism-"))
    status = 1
    try:
        status = check(work, args.flip)
    finally:
        if status == 0 and not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    return status


if __name__ == "__main__":
    sys.exit(main())
