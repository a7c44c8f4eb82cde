"""The CI's determinism check (.ci/determinism.py): its manifests name what differs, and its second pass
really holds numpy to its baseline code."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

SCRIPT = Path(__file__).resolve().parents[1] / ".ci" / "determinism.py"
_spec = importlib.util.spec_from_file_location("ci_determinism", SCRIPT)
determinism = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(determinism)


def _outputs(folder: Path, *, wall_time: float, estimate_last: float = 3.0) -> Path:
    (folder / "trial").mkdir(parents=True)
    np.savez(folder / "trial" / "frames.npz", t=np.arange(4.0), estimate=np.array([0.0, 1.0, 2.0, estimate_last]))
    (folder / "trial" / "map.pgm").write_bytes(b"P5 2 2 255\n" + bytes([0, 254, 205, 0]))
    (folder / "trial" / "run.json").write_text(
        json.dumps(
            {
                "seed": 1,
                "versions": {"numpy": "x"},
                "trial": {"duration_s": 172.2, "wall_time_s": wall_time, "explorer": {"plan_seconds": wall_time}},
                # a run's cost is a measurement of the machine, never a result
                "cost": {"slam_cpu_s": wall_time, "slam_peak_mib": 40.0 + wall_time, "update_ms_p90": wall_time},
            }
        )
    )
    (folder / "trial" / "timing.csv").write_text(f"frame,t,seconds\n0,0.0,{wall_time}\n")
    return folder


def test_manifests_of_the_same_results_agree_whatever_the_wall_clock_and_the_cost(tmp_path):
    a = determinism.manifest_of(_outputs(tmp_path / "a", wall_time=1.5))
    b = determinism.manifest_of(_outputs(tmp_path / "b", wall_time=9.25))
    assert set(a) == {"trial/frames.npz[t]", "trial/frames.npz[estimate]", "trial/map.pgm", "trial/run.json"}
    assert determinism.compare(a, b, "as-is", "baseline") == []


def test_a_flipped_byte_or_a_changed_array_is_named(tmp_path):
    a = determinism.manifest_of(_outputs(tmp_path / "a", wall_time=1.0))
    b_folder = _outputs(tmp_path / "b", wall_time=1.0, estimate_last=3.0000000000000004)
    determinism.flip_byte(b_folder / "trial" / "map.pgm")
    lines = determinism.compare(a, determinism.manifest_of(b_folder), "as-is", "baseline")
    assert [line.split(":")[0] for line in lines] == ["trial/frames.npz[estimate]", "trial/map.pgm"]
    (b_folder / "trial" / "map.pgm").unlink()
    lines = determinism.compare(a, determinism.manifest_of(b_folder), "as-is", "baseline")
    assert "trial/map.pgm: only in as-is" in lines


def test_the_baseline_pass_leaves_numpy_no_dispatched_simd_code(tmp_path):
    features, dispatch = determinism.numpy_dispatch()
    env = determinism.baseline_environment(tmp_path / "cache")
    named = env.get("NPY_DISABLE_CPU_FEATURES", "").split()
    assert set(named) <= {f for f in dispatch if features.get(f)}  # numpy rejects features the CPU lacks
    assert env["NUMBA_CPU_NAME"] == "generic" and env["NUMBA_CACHE_DIR"] == str(tmp_path / "cache")
    probe = (
        "import json, sys; sys.path.insert(0, sys.argv[1]); import determinism as d; "
        "f, dispatch = d.numpy_dispatch(); print(json.dumps([x for x in dispatch if f.get(x)]))"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe, str(SCRIPT.parent)], env=env, capture_output=True, text=True, check=True
    )
    assert json.loads(out.stdout) == []
